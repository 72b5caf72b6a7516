// QueuedSink: frames reach encode() in order on the worker thread; a stalled encoder
// never blocks publish() (the oldest frames are dropped and counted, the newest gets
// through once it resumes); exceptions become failures; idle() runs while no frame
// waits; stop() is idempotent and joins. Two threads: run by the TSan job.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pipeline/publish/queued_sink.h"

namespace mocap::publish {
namespace {

class RecordingSink final : public QueuedSink {
 public:
  explicit RecordingSink(int depth) : QueuedSink(depth) {}
  ~RecordingSink() override { stop(); }
  const char* name() const noexcept override { return "test"; }

  std::vector<std::uint64_t> sequences() {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }
  std::atomic<bool> block{false};
  std::atomic<bool> blocked{false};
  std::atomic<int> idles{0};
  std::atomic<std::uint64_t> throw_on{0};

 protected:
  void encode(const FrameResult& frame) override {
    while (block.load()) {
      blocked.store(true);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (frame.joints.sequence == throw_on.load()) throw std::runtime_error("transport down");
    std::lock_guard<std::mutex> lock(mutex_);
    seen_.push_back(frame.joints.sequence);
  }
  void idle() override { idles.fetch_add(1); }

 private:
  std::mutex mutex_;
  std::vector<std::uint64_t> seen_;
};

bool wait_for(const std::function<bool()>& pred) {
  for (int i = 0; i < 2000; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return pred();
}

TEST(QueuedSink, EncodesInOrderOnTheWorker) {
  auto sink = std::make_unique<RecordingSink>(64);
  ASSERT_TRUE(sink->start().ok());
  auto frame = std::make_unique<FrameResult>();
  for (std::uint64_t s = 1; s <= 20; ++s) {
    frame->joints.sequence = s;
    EXPECT_TRUE(sink->publish(*frame));
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_TRUE(wait_for([&] { return sink->counters().published == 20; }));
  const auto seqs = sink->sequences();
  ASSERT_EQ(seqs.size(), 20u);
  for (std::size_t i = 0; i < seqs.size(); ++i) EXPECT_EQ(seqs[i], i + 1);
  EXPECT_EQ(sink->counters().dropped, 0u);
  EXPECT_EQ(sink->counters().failures, 0u);
}

TEST(QueuedSink, StalledEncoderNeverBlocksPublish) {
  auto sink = std::make_unique<RecordingSink>(4);
  sink->block.store(true);
  ASSERT_TRUE(sink->start().ok());
  auto frame = std::make_unique<FrameResult>();
  frame->joints.sequence = 1;
  sink->publish(*frame);
  ASSERT_TRUE(wait_for([&] { return sink->blocked.load(); }));  // worker stuck in encode(1)
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t s = 2; s <= 1000; ++s) {
    frame->joints.sequence = s;
    sink->publish(*frame);
  }
  const auto dt = std::chrono::steady_clock::now() - t0;
  // 999 copies of ~13 KB: far below a second even under sanitizers; a blocking publish
  // would hang here for as long as the encoder is stalled (forever).
  EXPECT_LT(std::chrono::duration_cast<std::chrono::milliseconds>(dt).count(), 1000);
  EXPECT_EQ(sink->counters().dropped, 999u - 4u);
  sink->block.store(false);
  ASSERT_TRUE(wait_for([&] { return sink->counters().published == 5; }));
  const auto seqs = sink->sequences();
  const std::vector<std::uint64_t> expect{1, 997, 998, 999, 1000};
  EXPECT_EQ(seqs, expect);
}

TEST(QueuedSink, ExceptionsAreFailuresAndIdleRuns) {
  auto sink = std::make_unique<RecordingSink>(8);
  sink->throw_on.store(2);
  ASSERT_TRUE(sink->start().ok());
  auto frame = std::make_unique<FrameResult>();
  for (std::uint64_t s = 1; s <= 3; ++s) {
    frame->joints.sequence = s;
    sink->publish(*frame);
  }
  ASSERT_TRUE(wait_for([&] {
    const auto c = sink->counters();
    return c.published == 2 && c.failures == 1;
  }));
  ASSERT_TRUE(wait_for([&] { return sink->idles.load() >= 2; }));  // ~100 ms apart
  sink->stop();
  sink->stop();  // idempotent
  EXPECT_EQ(sink->sequences(), (std::vector<std::uint64_t>{1, 3}));
}

}  // namespace
}  // namespace mocap::publish
