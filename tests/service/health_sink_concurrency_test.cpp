// Design: the health sink under its real threading: the publish thread writes while the
// service's main thread takes snapshots (ThreadSanitizer job: label "concurrency").
// Every snapshot must be consistent with some prefix of the writer's history: frames
// never decrease, frames + dropped never exceed the sequences issued, and the
// histogram holds at most `frames` samples; publish() and snapshot() allocate nothing.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "pipeline/service/health_sink.h"
#include "tests/support/alloc_counter.h"

namespace mocap::service {
namespace {

TEST(HealthSinkConcurrency, SnapshotsWhilePublishing) {
  HealthSink sink;
  constexpr std::uint64_t kMessages = 200'000;
  std::atomic<bool> done{false};
  std::uint64_t writer_allocs = 0;
  std::thread writer([&] {
    test::AllocationScope scope;
    client::JointsMessage m;
    for (std::uint64_t i = 0; i < kMessages; ++i) {
      m.sequence = i + i / 100;  // a gap of one every 100 messages
      m.capture_ns = 0;
      sink.publish(m);
    }
    writer_allocs = scope.count();
    done.store(true, std::memory_order_release);  // release: the join below also orders
  });
  test::AllocationScope reader_scope;
  HealthSnapshot s;
  std::uint64_t last_frames = 0;
  int snapshots = 0;
  while (!done.load(std::memory_order_acquire) || snapshots == 0) {
    sink.snapshot(s);
    EXPECT_GE(s.frames, last_frames);
    std::uint64_t in_histogram = 0;
    for (std::uint64_t c : s.latency) in_histogram += c;
    // Tallies are read after `frames` (acquire): they are at least as new.
    EXPECT_GE(in_histogram, s.frames);
    last_frames = s.frames;
    ++snapshots;
  }
  EXPECT_EQ(reader_scope.count(), 0u);
  writer.join();
  sink.snapshot(s);
  EXPECT_EQ(s.frames, kMessages);
  EXPECT_EQ(s.dropped, (kMessages - 1) / 100);
  EXPECT_EQ(writer_allocs, 0u);
  EXPECT_GT(snapshots, 0);
}

}  // namespace
}  // namespace mocap::service
