// Benchmarks of mocap::rt::SpscRing against boost::lockfree::spsc_queue (compile-time
// capacity, allocation-free: the baseline), between two threads pinned to CPUs 0 and 1:
//   Throughput: the producer streams 1 Mi uint64 items, the consumer pops them.
//   RoundTrip : ping through one ring, pong back through another (one round trip per
//               iteration): the latency a stage hand-off adds, twice.
// Also the SlotPool hand-off (acquire, publish, pop, release) of one frame slot.
#include <benchmark/benchmark.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "rt/slot_pool.h"
#include "rt/spsc_ring.h"

#if __has_include(<boost/lockfree/spsc_queue.hpp>)
#include <boost/lockfree/spsc_queue.hpp>
#define MOCAP_HAVE_BOOST_LOCKFREE 1
#endif

namespace {

constexpr std::size_t kCapacity = 1024;
constexpr std::uint64_t kBatch = 1u << 20;

void pin_to(int cpu) {
  if (cpu < 0 || cpu >= static_cast<int>(std::thread::hardware_concurrency())) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

struct OwnRing {
  mocap::rt::SpscRing<std::uint64_t> q{kCapacity};
  bool push(std::uint64_t v) noexcept { return q.try_push(v); }
  bool pop(std::uint64_t& v) noexcept { return q.try_pop(v); }
};

#ifdef MOCAP_HAVE_BOOST_LOCKFREE
struct BoostRing {
  boost::lockfree::spsc_queue<std::uint64_t, boost::lockfree::capacity<kCapacity>> q;
  bool push(std::uint64_t v) noexcept { return q.push(v); }
  bool pop(std::uint64_t& v) noexcept { return q.pop(v); }
};
#endif

template <class Ring>
void BM_Throughput(benchmark::State& state) {
  pin_to(0);
  auto ring = std::make_unique<Ring>();
  std::uint64_t sum = 0;
  for (auto _ : state) {
    std::thread producer([&] {
      pin_to(1);
      for (std::uint64_t i = 0; i < kBatch; ++i) {
        while (!ring->push(i)) {
        }
      }
    });
    for (std::uint64_t n = 0; n < kBatch;) {
      std::uint64_t v;
      if (ring->pop(v)) {
        sum += v;
        ++n;
      }
    }
    producer.join();
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
}

template <class Ring>
void BM_RoundTrip(benchmark::State& state) {
  pin_to(0);
  auto ping = std::make_unique<Ring>();
  auto pong = std::make_unique<Ring>();
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    pin_to(1);
    std::uint64_t v;
    while (!stop.load(std::memory_order_relaxed)) {
      if (ping->pop(v)) {
        while (!pong->push(v)) {
        }
      }
    }
  });
  std::uint64_t i = 0;
  for (auto _ : state) {
    while (!ping->push(i)) {
    }
    std::uint64_t v;
    while (!pong->pop(v)) {
    }
    benchmark::DoNotOptimize(v);
    ++i;
  }
  stop.store(true, std::memory_order_relaxed);
  echo.join();
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

// Push then pop on one thread: the instruction cost of the two calls without any
// cache-line transfer (insensitive to machine load, unlike the two-thread runs).
template <class Ring>
void BM_PushPopSameThread(benchmark::State& state) {
  auto ring = std::make_unique<Ring>();
  std::uint64_t i = 0, v = 0;
  for (auto _ : state) {
    ring->push(i++);
    ring->pop(v);
    benchmark::DoNotOptimize(v);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

// One frame slot's full cycle on one thread (no contention): the fixed cost a stage
// pays per frame for the pool's ownership passing.
void BM_SlotPoolCycle(benchmark::State& state) {
  struct Slot {
    std::uint64_t sequence = 0;
  };
  auto pool = mocap::rt::SlotPool<Slot>::create(8, [](std::uint32_t) { return Slot{}; });
  mocap::rt::SlotHandle h = 0;
  for (auto _ : state) {
    pool->acquire(h);
    (*pool)[h].sequence++;
    pool->publish(h);
    pool->pop_latest(h);
    pool->release(h);
  }
  benchmark::DoNotOptimize(h);
}

}  // namespace

BENCHMARK_TEMPLATE(BM_Throughput, OwnRing)
    ->Name("Throughput/mocap_SpscRing")
    ->UseRealTime()
    ->MinTime(0.5);
BENCHMARK_TEMPLATE(BM_RoundTrip, OwnRing)
    ->Name("RoundTrip/mocap_SpscRing")
    ->UseRealTime()
    ->MinTime(0.5);
#ifdef MOCAP_HAVE_BOOST_LOCKFREE
BENCHMARK_TEMPLATE(BM_Throughput, BoostRing)
    ->Name("Throughput/boost_spsc_queue")
    ->UseRealTime()
    ->MinTime(0.5);
BENCHMARK_TEMPLATE(BM_RoundTrip, BoostRing)
    ->Name("RoundTrip/boost_spsc_queue")
    ->UseRealTime()
    ->MinTime(0.5);
#endif
BENCHMARK_TEMPLATE(BM_PushPopSameThread, OwnRing)->Name("PushPop1T/mocap_SpscRing");
#ifdef MOCAP_HAVE_BOOST_LOCKFREE
BENCHMARK_TEMPLATE(BM_PushPopSameThread, BoostRing)->Name("PushPop1T/boost_spsc_queue");
#endif
BENCHMARK(BM_SlotPoolCycle);

BENCHMARK_MAIN();
