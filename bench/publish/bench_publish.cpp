// Design: per-message costs of the live output. CRC-32 of a full datagram body (ours,
// slicing-by-8, vs zlib's crc32 as the baseline), encode_datagram (packing + CRC) and
// decode_datagram (validation + unpacking) for 1, 8 and 32 joints, and UdpPublisher ->
// UdpReceiver on 127.0.0.1 (sendto + recv per message). Loopback only. With a running
// iox-roudi (start it yourself, e.g. with the small config of docs/performance.md (live output section))
// also the iceoryx loan + copy + publish, and publish + take; otherwise those are skipped.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "client/crc32.h"
#include "client/datagram.h"
#include "client/udp_receiver.h"
#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/udp_publisher.h"
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
#include "client/iceoryx_subscriber.h"
#include "client/roudi_probe.h"
#endif

#ifdef MOCAP_BENCH_HAVE_ZLIB
#include <zlib.h>
#endif

namespace {

using namespace mocap::client;

JointsMessage make_message(std::uint16_t joints) {
  JointsMessage m;
  m.sequence = 42;
  m.capture_ns = 123456789;
  m.publish_ns = 123456999;
  m.joint_count = joints;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::uint16_t j = 0; j < joints; ++j) {
    m.joints[j].index = j;
    m.joints[j].valid = 1;
    for (float& a : m.joints[j].a) a = u(rng);
    for (float& q : m.joints[j].q) q = u(rng);
  }
  return m;
}

std::vector<std::uint8_t> body_bytes(std::size_t n) {
  std::vector<std::uint8_t> b(n);
  std::mt19937 rng(2);
  for (auto& x : b) x = static_cast<std::uint8_t>(rng());
  return b;
}

void BM_Crc32Ours(benchmark::State& state) {
  const auto b = body_bytes(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(crc32_ieee(b.data(), b.size()));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Crc32Ours)->Arg(72)->Arg(296)->Arg(1064);

#ifdef MOCAP_BENCH_HAVE_ZLIB
void BM_Crc32Zlib(benchmark::State& state) {
  const auto b = body_bytes(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(::crc32(0L, b.data(), static_cast<uInt>(b.size())));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Crc32Zlib)->Arg(72)->Arg(296)->Arg(1064);
#endif

void BM_EncodeDatagram(benchmark::State& state) {
  const JointsMessage m = make_message(static_cast<std::uint16_t>(state.range(0)));
  std::vector<std::uint8_t> buf(kMaxDatagramBytes);
  for (auto _ : state) {
    benchmark::DoNotOptimize(encode_datagram(m, buf.data(), buf.size()));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_EncodeDatagram)->Arg(1)->Arg(8)->Arg(32);

void BM_DecodeDatagram(benchmark::State& state) {
  const JointsMessage m = make_message(static_cast<std::uint16_t>(state.range(0)));
  std::vector<std::uint8_t> buf(kMaxDatagramBytes);
  const std::size_t n = encode_datagram(m, buf.data(), buf.size());
  JointsMessage out;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decode_datagram(buf.data(), n, out));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_DecodeDatagram)->Arg(1)->Arg(8)->Arg(32);

// One publish (encode + sendto) and one receive (recv + validate) per iteration.
void BM_UdpLoopbackPublishReceive(benchmark::State& state) {
  auto rx = UdpReceiver::create("127.0.0.1:0");
  if (!rx) {
    state.SkipWithError(rx.error().message.c_str());
    return;
  }
  auto pub = mocap::publish::UdpPublisher::create({"127.0.0.1:" + std::to_string(rx->port())});
  if (!pub) {
    state.SkipWithError(pub.error().message.c_str());
    return;
  }
  JointsMessage m = make_message(static_cast<std::uint16_t>(state.range(0)));
  for (auto _ : state) {
    ++m.sequence;
    pub->publish(m);
    benchmark::DoNotOptimize(rx->poll());
  }
  state.counters["accepted"] = static_cast<double>(rx->counters().accepted);
  state.counters["dropped"] = static_cast<double>(rx->counters().dropped_frames);
  state.counters["send_fail"] =
      static_cast<double>(pub->counters().would_block + pub->counters().other_errors);
}
BENCHMARK(BM_UdpLoopbackPublishReceive)->Arg(8)->Arg(32);

// sendto only (the tracker's per-frame cost); the receiver drains every 64 messages.
void BM_UdpLoopbackPublishOnly(benchmark::State& state) {
  auto rx = UdpReceiver::create("127.0.0.1:0");
  auto pub = mocap::publish::UdpPublisher::create(
      {"127.0.0.1:" + std::to_string(rx.ok() ? rx->port() : 9)});
  if (!rx || !pub) {
    state.SkipWithError("setup failed");
    return;
  }
  JointsMessage m = make_message(static_cast<std::uint16_t>(state.range(0)));
  std::uint64_t i = 0;
  for (auto _ : state) {
    ++m.sequence;
    pub->publish(m);
    if ((++i & 63u) == 0) {
      state.PauseTiming();
      rx->poll();
      state.ResumeTiming();
    }
  }
}
BENCHMARK(BM_UdpLoopbackPublishOnly)->Arg(8)->Arg(32);

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
// One process runtime for both iceoryx benchmarks (created on first use).
struct IceoryxEnd {
  std::unique_ptr<mocap::publish::IceoryxPublisher> pub;
  std::unique_ptr<IceoryxSubscriber> sub;
  std::string error;
};
IceoryxEnd& iceoryx_end() {
  static IceoryxEnd end = [] {
    IceoryxEnd e;
    if (!roudi_running()) {
      e.error = "iox-roudi not running";
      return e;
    }
    const std::string name = "mocap_bench_" + std::to_string(::getpid());
    auto p = mocap::publish::IceoryxPublisher::create(name);
    auto s = IceoryxSubscriber::create(name);
    if (!p || !s) {
      e.error = !p ? p.error().message : s.error().message;
      return e;
    }
    e.pub = std::move(p.value());
    e.sub = std::move(s.value());
    return e;
  }();
  return end;
}

void BM_IceoryxPublish(benchmark::State& state) {
  IceoryxEnd& e = iceoryx_end();
  if (!e.pub) {
    state.SkipWithError(e.error.c_str());
    return;
  }
  JointsMessage m = make_message(32);
  JointsMessage out;
  std::uint64_t i = 0;
  for (auto _ : state) {
    ++m.sequence;
    benchmark::DoNotOptimize(e.pub->publish(m));
    if ((++i & 7u) == 0) {  // keep the subscriber queue short, outside the timing
      state.PauseTiming();
      e.sub->take_latest(out);
      state.ResumeTiming();
    }
  }
}
BENCHMARK(BM_IceoryxPublish);

void BM_IceoryxPublishTake(benchmark::State& state) {
  IceoryxEnd& e = iceoryx_end();
  if (!e.pub) {
    state.SkipWithError(e.error.c_str());
    return;
  }
  JointsMessage m = make_message(32);
  JointsMessage out;
  for (auto _ : state) {
    ++m.sequence;
    e.pub->publish(m);
    benchmark::DoNotOptimize(e.sub->take_latest(out));
  }
}
BENCHMARK(BM_IceoryxPublishTake);
#endif

}  // namespace

BENCHMARK_MAIN();
