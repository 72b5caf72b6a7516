// Design: what a QueuedSink costs the real-time publish thread per frame. Three cases:
// the floor (one FrameResult copy, ~55.6 KiB, into a preallocated buffer: what any queued
// hand-off must pay), publish() while the worker is blocked inside encode() (queue full:
// copy + drop-oldest), and publish() to a worker that is asleep between its polls (the
// common case at 100 fps; since 2026-12-02 no wake syscall either: the worker polls every
// 1 ms; measured with the timer paused while the worker drains and goes back to sleep).
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <thread>

#include "pipeline/publish/queued_sink.h"

namespace {

using mocap::publish::FrameResult;

class BenchSink final : public mocap::publish::QueuedSink {
 public:
  BenchSink() : QueuedSink(8) {}
  ~BenchSink() override {
    block.store(false);
    stop();
  }
  const char* name() const noexcept override { return "bench"; }
  std::atomic<bool> block{false};

 protected:
  void encode(const FrameResult& f) override {
    while (block.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    benchmark::DoNotOptimize(f.joints.sequence);
  }
};

void BM_FrameResultCopyFloor(benchmark::State& state) {
  auto a = std::make_unique<FrameResult>();
  auto b = std::make_unique<FrameResult>();
  for (auto _ : state) {
    a->joints.sequence++;
    std::memcpy(static_cast<void*>(b.get()), a.get(), sizeof(FrameResult));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * sizeof(FrameResult)));
}
BENCHMARK(BM_FrameResultCopyFloor);

void BM_QueuedSinkPublishWorkerBusy(benchmark::State& state) {
  BenchSink sink;
  sink.block.store(true);
  (void)sink.start();
  auto f = std::make_unique<FrameResult>();
  for (auto _ : state) {
    f->joints.sequence++;
    sink.publish(*f);
  }
  state.counters["dropped"] = static_cast<double>(sink.counters().dropped);
}
BENCHMARK(BM_QueuedSinkPublishWorkerBusy);

void BM_QueuedSinkPublishWorkerAsleep(benchmark::State& state) {
  BenchSink sink;
  (void)sink.start();
  auto f = std::make_unique<FrameResult>();
  std::uint64_t n = 0;
  for (auto _ : state) {
    f->joints.sequence++;
    sink.publish(*f);
    ++n;
    state.PauseTiming();
    while (sink.counters().published < n) std::this_thread::yield();
    std::this_thread::sleep_for(std::chrono::microseconds(300));  // worker back asleep
    state.ResumeTiming();
  }
}
BENCHMARK(BM_QueuedSinkPublishWorkerAsleep)->Iterations(2000);

}  // namespace

BENCHMARK_MAIN();
