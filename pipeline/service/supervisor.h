// Design: the service state machine of `mocap run`, polled by the main thread (every
// ~20 ms) while the pipeline runs; the pipeline's threads never see it.
//
//   kStarting --first frame at the end of the pipeline--> kRunning --stop--> kStopping
//      STATUS=starting...          READY=1                 WATCHDOG=1 only while frames
//                                                          progress; STATUS=fps/p99/drops
//
// Watchdog: every watchdog_usec / 2 the supervisor pings WATCHDOG=1 ONLY if more frames
// reached the end of the pipeline since the previous ping. A stalled pipeline (camera
// gone, a stage hung) therefore stops the pings even though this thread is alive, and
// systemd's WatchdogSec= restarts the service; once frames flow again the next poll
// pings at once. Status: every status_interval a STATUS= line with the window's frame
// rate, trigger-to-publish p99 over the window (the pipeline's end-to-end histogram) and
// drops (window and total), all from the one health view (pipeline/pipeline_health.h);
// every log_interval the same line on stderr (the journal). Repeated problems (a stall)
// are logged at once and then at most once per log_interval with a suppressed count.
// Time is passed in (CLOCK_MONOTONIC ns), so tests drive it deterministically.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "core/latency_histogram.h"
#include "pipeline/pipeline_health.h"
#include "pipeline/service/notifier.h"

namespace mocap::service {

struct SupervisorOptions {
  double status_interval_s = 1.0;
  double log_interval_s = 0.0;  // 0: no periodic statistics line
  std::FILE* log = stderr;      // nullptr: silent
};

class Supervisor {
 public:
  enum class State : std::uint8_t { kStarting, kRunning, kStopping };

  Supervisor(const pipeline::HealthSource& health, Notifier& notifier,
             const SupervisorOptions& options);

  void poll(std::int64_t now_ns);
  // STOPPING=1 (once), before the pipeline is stopped.
  void stopping();

  State state() const noexcept { return state_; }
  std::uint64_t watchdog_pings() const noexcept { return pings_; }
  const std::string& last_status() const noexcept { return last_status_; }

 private:
  void send_status(std::int64_t now_ns);
  LatencySnapshot latency_now() const;
  void log_line(const std::string& line);

  const pipeline::HealthSource& health_;
  Notifier& notifier_;
  SupervisorOptions options_;
  State state_ = State::kStarting;
  std::int64_t ping_period_ns_ = 0;  // 0: no watchdog
  std::int64_t status_period_ns_ = 0;
  std::int64_t log_period_ns_ = 0;

  pipeline::PipelineHealth snap_;    // current
  pipeline::PipelineHealth window_;  // at the previous STATUS
  LatencySnapshot window_latency_;   // the end-to-end histogram at the previous STATUS
  std::int64_t window_ns_ = 0;       // time of window_
  std::int64_t next_status_ns_ = 0;
  std::int64_t next_log_ns_ = 0;
  std::int64_t next_ping_ns_ = 0;
  std::uint64_t ping_frames_ = 0;  // frames at the previous ping
  std::uint64_t pings_ = 0;
  std::string last_status_;

  // Stall reporting (rate limited).
  std::uint64_t progress_frames_ = 0;
  std::int64_t progress_ns_ = 0;  // when frames last advanced
  bool stalled_ = false;
  std::int64_t next_stall_log_ns_ = 0;
  std::uint64_t stall_suppressed_ = 0;
};

}  // namespace mocap::service
