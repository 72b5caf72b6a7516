// Design: what the VRPN output costs, with N connected TCP clients (0, 1, 4, 8) that a
// reader thread drains: (1) publish() on the real-time publish thread (the QueuedSink
// copy; independent of N by design), (2) the server thread's work per frame (encode the
// reports once, copy them to every client's buffer, send) for the 15 bodies of the
// humanoid with velocities, (3) the report encoding alone for 32 bodies.
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/vrpn/vrpn_reports.h"
#include "pipeline/publish/vrpn/vrpn_server.h"

namespace {

using namespace mocap::publish;

std::int64_t bench_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

FrameResult bench_frame(int bodies) {
  FrameResult f;
  f.body_count = bodies;
  for (int b = 0; b < bodies; ++b) {
    ResultBody& r = f.bodies[static_cast<std::size_t>(b)];
    r.found = 1;
    r.velocity_valid = 1;
    r.t_world_body_mm = {100.0 * b, 50.0, 900.0};
    r.w_world_rad_s = {0.1f, 0.2f, 0.3f};
  }
  return f;
}

// N clients connected to 127.0.0.1:port with their cookie sent, drained by a thread.
struct Readers {
  Readers(std::uint16_t port, int n) {
    for (int i = 0; i < n; ++i) {
      const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_port = htons(port);
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
      char cookie[24] = "vrpn: ver. 07.35  0";
      ::send(fd, cookie, sizeof cookie, 0);
      fds.push_back({fd, POLLIN, 0});
    }
    thread = std::thread([this] {
      char buf[65536];
      while (!stop.load(std::memory_order_relaxed)) {
        if (::poll(fds.data(), fds.size(), 5) <= 0) continue;
        for (pollfd& p : fds)
          if ((p.revents & POLLIN) != 0) (void)::recv(p.fd, buf, sizeof buf, MSG_DONTWAIT);
      }
    });
  }
  ~Readers() {
    stop.store(true);
    thread.join();
    for (pollfd& p : fds) ::close(p.fd);
  }
  std::vector<pollfd> fds;
  std::atomic<bool> stop{false};
  std::thread thread;
};

void BM_VrpnServerFrame(benchmark::State& state) {
  std::vector<std::string> names;
  for (int b = 0; b < 15; ++b) names.push_back("body" + std::to_string(b));
  vrpn::ServerOptions o;
  o.port = 0;
  auto server = std::move(vrpn::Server::create(o, names).value());
  Readers readers(server->port(), static_cast<int>(state.range(0)));
  for (int i = 0; i < 50; ++i) {  // accept and read the cookies
    server->poll(bench_now_ns());
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const FrameResult f = bench_frame(15);
  for (auto _ : state) {
    const std::int64_t now = bench_now_ns();
    server->poll(now);
    server->send_frame(f, 0, now);
  }
  state.counters["dropped"] = static_cast<double>(server->counters().frames_dropped);
  state.counters["clients"] = server->counters().clients_active;
}
BENCHMARK(BM_VrpnServerFrame)->Arg(0)->Arg(1)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond);

void BM_VrpnPublish(benchmark::State& state) {
  mocap::TargetSet targets;
  for (int b = 0; b < 15; ++b)
    targets.bodies.push_back(mocap::MarkerTarget{"body" + std::to_string(b), {}});
  OutputContext ctx;
  ctx.targets = &targets;
  auto outputs =
      std::move(create_outputs({OutputRequest{"vrpn", {"127.0.0.1:0"}, "bench", {}}}, ctx).value());
  const std::string& n = outputs.notices.at(0);
  const auto port = static_cast<std::uint16_t>(std::stoi(n.substr(n.find("127.0.0.1:") + 10)));
  Readers readers(port, static_cast<int>(state.range(0)));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the server thread accepts
  const FrameResult f = bench_frame(15);
  OutputSink* sink = outputs.sinks.at(0).get();
  for (auto _ : state) benchmark::DoNotOptimize(sink->publish(f));
}
BENCHMARK(BM_VrpnPublish)->Arg(0)->Arg(8)->Unit(benchmark::kMicrosecond);

void BM_VrpnEncodeReports(benchmark::State& state) {
  const FrameResult f = bench_frame(32);
  std::vector<std::uint8_t> out(32 * vrpn::kReportBytes);
  std::uint32_t seq = 0;
  for (auto _ : state) {
    std::uint64_t reports = 0;
    benchmark::DoNotOptimize(vrpn::encode_frame_reports(f, 32, 0.01, vrpn::WireTime{1, 2}, seq,
                                                        out.data(), out.size(), reports));
  }
}
BENCHMARK(BM_VrpnEncodeReports)->Unit(benchmark::kMicrosecond);

}  // namespace
BENCHMARK_MAIN();
