// Design: the service state machine driven by a scripted health source and a recording
// notifier, on a virtual clock: READY only after the first frame, WATCHDOG at half the
// watchdog timeout and only while frames progress, pings resume with the frames,
// STATUS carries the window's fps, p99 and drops; plus the latency histogram's bucket
// arithmetic and the health sink's drop counting.
#include "pipeline/service/supervisor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pipeline/service/health_sink.h"

namespace mocap::service {
namespace {

constexpr std::int64_t kMs = 1'000'000;

class FakeHealth final : public HealthSource {
 public:
  void snapshot(HealthSnapshot& out) const noexcept override { out = snap; }
  void add_frames(std::uint64_t n, std::uint64_t latency_us) {
    snap.frames += n;
    snap.latency[static_cast<std::size_t>(latency_bucket(latency_us))] += n;
  }
  HealthSnapshot snap;
};

class RecordingNotifier final : public Notifier {
 public:
  explicit RecordingNotifier(std::uint64_t usec) : usec_(usec) {}
  bool notify(const std::string& state) noexcept override {
    sent.push_back(state);
    return true;
  }
  std::uint64_t watchdog_usec() const noexcept override { return usec_; }
  int count(const std::string& s) const {
    return static_cast<int>(std::count(sent.begin(), sent.end(), s));
  }
  std::vector<std::string> sent;

 private:
  std::uint64_t usec_;
};

SupervisorOptions quiet(double status_s = 1.0) {
  SupervisorOptions o;
  o.status_interval_s = status_s;
  o.log = nullptr;
  return o;
}

TEST(Supervisor, ReadyOnlyAfterTheFirstFrame) {
  FakeHealth h;
  RecordingNotifier n(200'000);
  Supervisor s(h, n, quiet());
  for (std::int64_t t = 0; t < 2000 * kMs; t += 20 * kMs) s.poll(t);
  EXPECT_EQ(n.count("READY=1"), 0);
  EXPECT_EQ(n.count("WATCHDOG=1"), 0);  // never a ping before READY
  EXPECT_EQ(s.state(), Supervisor::State::kStarting);
  h.add_frames(1, 500);
  s.poll(2000 * kMs);
  EXPECT_EQ(n.count("READY=1"), 1);
  EXPECT_EQ(s.state(), Supervisor::State::kRunning);
  s.poll(2020 * kMs);
  EXPECT_EQ(n.count("READY=1"), 1);
}

TEST(Supervisor, WatchdogAtHalfTheTimeoutWhileFramesProgress) {
  FakeHealth h;
  RecordingNotifier n(200'000);  // WatchdogSec=200ms: ping every 100 ms
  Supervisor s(h, n, quiet());
  std::int64_t t = 0;
  for (; t <= 1000 * kMs; t += 10 * kMs) {
    h.add_frames(1, 800);
    s.poll(t);
  }
  // READY at t=0, pings at 100, 200, ..., 1000 ms.
  EXPECT_EQ(s.watchdog_pings(), 10u);
  EXPECT_EQ(n.count("WATCHDOG=1"), 10);
}

TEST(Supervisor, NoWatchdogWhileStalledAndPingsResumeWithFrames) {
  FakeHealth h;
  RecordingNotifier n(200'000);
  Supervisor s(h, n, quiet(0.1));
  std::int64_t t = 0;
  for (; t < 500 * kMs; t += 10 * kMs) {
    h.add_frames(1, 800);
    s.poll(t);
  }
  // The frames since the last ping still earn one ping when it is due (500 ms).
  for (; t < 600 * kMs; t += 10 * kMs) s.poll(t);
  const std::uint64_t before = s.watchdog_pings();
  EXPECT_EQ(before, 5u);
  for (; t < 1500 * kMs; t += 10 * kMs) s.poll(t);  // the process is alive, frames are not
  EXPECT_EQ(s.watchdog_pings(), before);
  EXPECT_NE(s.last_status().find("STALLED"), std::string::npos) << s.last_status();
  h.add_frames(1, 800);
  s.poll(t);
  EXPECT_EQ(s.watchdog_pings(), before + 1);  // at once, not a period later
}

TEST(Supervisor, NoWatchdogWithoutWatchdogUsec) {
  FakeHealth h;
  RecordingNotifier n(0);
  Supervisor s(h, n, quiet());
  for (std::int64_t t = 0; t < 1000 * kMs; t += 10 * kMs) {
    h.add_frames(1, 800);
    s.poll(t);
  }
  EXPECT_EQ(n.count("READY=1"), 1);
  EXPECT_EQ(n.count("WATCHDOG=1"), 0);
}

TEST(Supervisor, StatusCarriesFpsP99AndDrops) {
  FakeHealth h;
  RecordingNotifier n(0);
  Supervisor s(h, n, quiet(1.0));
  h.add_frames(1, 1000);
  s.poll(0);  // READY; the status window starts here
  // One second at 100 fps: 99 frames at 1.0 ms and 1 at 7.5 ms, 3 drops.
  for (int i = 1; i <= 100; ++i) {
    h.add_frames(1, i == 50 ? 7500 : 1000);
    if (i % 25 == 0) h.snap.dropped += 1;
    s.poll(i * 10 * kMs);
  }
  const std::string& st = s.last_status();
  EXPECT_NE(st.find("100.0 fps"), std::string::npos) << st;
  // p99 of 100 samples is the 99th: 1.0 ms, reported as its bucket's upper edge (1.024).
  EXPECT_NE(st.find("p99 1.02 ms"), std::string::npos) << st;
  EXPECT_NE(st.find("dropped 4 (total 4)"), std::string::npos) << st;
  EXPECT_EQ(n.sent.back(), "STATUS=" + st);
}

TEST(Supervisor, StoppingOnce) {
  FakeHealth h;
  RecordingNotifier n(200'000);
  Supervisor s(h, n, quiet());
  s.stopping();
  s.stopping();
  h.add_frames(5, 100);
  s.poll(0);
  EXPECT_EQ(n.count("STOPPING=1"), 1);
  EXPECT_EQ(n.count("READY=1"), 0);
}

TEST(LatencyHistogram, BucketsAreMonotonicAndBoundTheirValues) {
  int prev = -1;
  for (std::uint64_t us = 0; us < (1u << 22); us = us < 64 ? us + 1 : us + us / 7) {
    const int b = latency_bucket(us);
    EXPECT_GE(b, prev);
    EXPECT_LT(b, kLatencyBuckets - 1);
    EXPECT_GT(bucket_upper_us(b), static_cast<double>(us));  // upper edge is exclusive
    if (b > 0) {
      EXPECT_LE(bucket_upper_us(b - 1), static_cast<double>(us));
    }
    // Resolution: a bucket is at most 12.5 % (plus 1 us at the exact low end) wide.
    const double lower = b > 0 ? bucket_upper_us(b - 1) : 0.0;
    EXPECT_LE(bucket_upper_us(b) - lower, std::max(1.0, 0.125 * bucket_upper_us(b) + 1e-9));
    prev = b;
  }
  EXPECT_EQ(latency_bucket(std::uint64_t{1} << 40), kLatencyBuckets - 1);
}

TEST(LatencyHistogram, WindowQuantile) {
  HealthSnapshot a, b;
  EXPECT_EQ(window_quantile_us(b, a, 0.99), 0.0);
  b.latency[static_cast<std::size_t>(latency_bucket(100))] = 98;
  b.latency[static_cast<std::size_t>(latency_bucket(5000))] = 2;
  EXPECT_GT(window_quantile_us(b, a, 0.99), 5000.0);
  EXPECT_LT(window_quantile_us(b, a, 0.99), 5000.0 * 1.125);
  EXPECT_LT(window_quantile_us(b, a, 0.50), 120.0);
  a = b;  // an empty window
  EXPECT_EQ(window_quantile_us(b, a, 0.99), 0.0);
}

TEST(HealthSink, CountsFramesAndSequenceGaps) {
  HealthSink sink;
  client::JointsMessage m;
  for (std::uint64_t seq : {2u, 3u, 4u, 7u, 8u, 8u, 20u}) {
    m.sequence = seq;
    m.capture_ns = 0;  // far in the past: lands in the overflow bucket
    EXPECT_TRUE(sink.publish(m));
  }
  HealthSnapshot s;
  sink.snapshot(s);
  EXPECT_EQ(s.frames, 7u);
  EXPECT_EQ(s.dropped, 2u + 2u + 11u);  // 0-1, 5-6, 9-19 never arrived
  EXPECT_GT(s.last_ns, 0);
  EXPECT_EQ(s.latency[kLatencyBuckets - 1], 7u);
}

}  // namespace
}  // namespace mocap::service
