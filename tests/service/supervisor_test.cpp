// Design: the service state machine driven by a scripted health source and a recording
// notifier, on a virtual clock: READY only after the first frame, WATCHDOG at half the
// watchdog timeout and only while frames progress, pings resume with the frames,
// STATUS carries the window's fps, p99 (of the window, not since the start) and drops.
#include "pipeline/service/supervisor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/latency_histogram.h"

namespace mocap::service {
namespace {

constexpr std::int64_t kMs = 1'000'000;

class FakeHealth final : public pipeline::HealthSource {
 public:
  pipeline::PipelineHealth health() const noexcept override { return snap; }
  const LatencyHistogram* end_to_end() const noexcept override { return &latency; }
  void add_frames(std::uint64_t n, std::int64_t latency_us) {
    snap.frames_published += n;
    for (std::uint64_t i = 0; i < n; ++i) latency.record(latency_us * 1000);
  }
  pipeline::PipelineHealth snap;
  LatencyHistogram latency;
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
    if (i % 25 == 0) h.snap.frames_dropped += 1;
    s.poll(i * 10 * kMs);
  }
  const std::string& st = s.last_status();
  EXPECT_NE(st.find("100.0 fps"), std::string::npos) << st;
  // p99 of the window's 100 samples is the 99th: 1.0 ms (its bucket's upper edge, at most
  // 1/64 above); the 1 ms frame before the window does not count.
  EXPECT_NE(st.find("p99 1.01 ms"), std::string::npos) << st;
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

TEST(Supervisor, StatusP99IsTheWindowsNotSinceTheStart) {
  FakeHealth h;
  RecordingNotifier n(0);
  Supervisor s(h, n, quiet(1.0));
  h.add_frames(1, 1000);
  s.poll(0);
  for (int i = 1; i <= 100; ++i) {  // a slow first second: 20 ms per frame
    h.add_frames(1, 20'000);
    s.poll(i * 10 * kMs);
  }
  EXPECT_NE(s.last_status().find("p99 20."), std::string::npos) << s.last_status();
  for (int i = 101; i <= 200; ++i) {  // then fast: the window forgets the slow second
    h.add_frames(1, 500);
    s.poll(i * 10 * kMs);
  }
  EXPECT_NE(s.last_status().find("p99 0.50 ms"), std::string::npos) << s.last_status();
}

}  // namespace
}  // namespace mocap::service
