// Design: see supervisor.h.
#include "pipeline/service/supervisor.h"

#include <cinttypes>
#include <utility>

namespace mocap::service {

namespace {

std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(s * 1e9); }

}  // namespace

Supervisor::Supervisor(const pipeline::HealthSource& health, Notifier& notifier,
                       const SupervisorOptions& options)
    : health_(health), notifier_(notifier), options_(options) {
  ping_period_ns_ = static_cast<std::int64_t>(notifier_.watchdog_usec()) * 1000 / 2;
  status_period_ns_ = seconds_to_ns(options_.status_interval_s);
  log_period_ns_ = seconds_to_ns(options_.log_interval_s);
  notifier_.notify("STATUS=starting: waiting for the first frames from the cameras");
}

void Supervisor::log_line(const std::string& line) {
  if (options_.log == nullptr) return;
  std::fprintf(options_.log, "mocap run: %s\n", line.c_str());
  std::fflush(options_.log);
}

void Supervisor::poll(std::int64_t now_ns) {
  if (state_ == State::kStopping) return;
  snap_ = health_.health();
  if (snap_.frames_published != progress_frames_ || progress_ns_ == 0) {
    if (stalled_ && snap_.frames_published != progress_frames_) {
      log_line("pipeline running again after a stall of " +
               std::to_string((now_ns - progress_ns_) / 1'000'000) + " ms");
      stalled_ = false;
    }
    progress_frames_ = snap_.frames_published;
    progress_ns_ = now_ns;
  }

  if (state_ == State::kStarting) {
    if (snap_.frames_published == 0) return;
    state_ = State::kRunning;
    notifier_.notify("READY=1");
    log_line("ready: the cameras deliver and frames reach the outputs");
    ping_frames_ = snap_.frames_published;
    next_ping_ns_ = now_ns + ping_period_ns_;
    window_ = snap_;
    window_latency_ = latency_now();
    window_ns_ = now_ns;
    next_status_ns_ = now_ns + status_period_ns_;
    next_log_ns_ = now_ns + log_period_ns_;
    notifier_.notify("STATUS=running: first frames processed");
    return;
  }

  if (ping_period_ns_ > 0 && now_ns >= next_ping_ns_ && snap_.frames_published > ping_frames_) {
    notifier_.notify("WATCHDOG=1");
    ++pings_;
    ping_frames_ = snap_.frames_published;
    next_ping_ns_ = now_ns + ping_period_ns_;
  }

  // A stall: no frame for longer than a status interval (and at least 200 ms).
  const std::int64_t stall_ns = status_period_ns_ > 200'000'000 ? status_period_ns_ : 200'000'000;
  if (now_ns - progress_ns_ >= stall_ns) {
    if (!stalled_ || now_ns >= next_stall_log_ns_) {
      std::string line = "pipeline stalled: no frame reached the outputs for " +
                         std::to_string((now_ns - progress_ns_) / 1'000'000) +
                         " ms (cameras? see docs/operations.md); watchdog withheld";
      if (stall_suppressed_ > 0)
        line += " (" + std::to_string(stall_suppressed_) + " similar messages suppressed)";
      log_line(line);
      stall_suppressed_ = 0;
      stalled_ = true;
      next_stall_log_ns_ = now_ns + (log_period_ns_ > 0 ? log_period_ns_ : seconds_to_ns(10.0));
    } else {
      ++stall_suppressed_;
    }
  }

  if (now_ns >= next_status_ns_) send_status(now_ns);
}

LatencySnapshot Supervisor::latency_now() const {
  const LatencyHistogram* e2e = health_.end_to_end();
  return e2e != nullptr ? e2e->snapshot() : LatencySnapshot{};
}

void Supervisor::send_status(std::int64_t now_ns) {
  const pipeline::PipelineHealth& snap = snap_;
  const double dt_s = static_cast<double>(now_ns - window_ns_) * 1e-9;
  const std::uint64_t frames = snap.frames_published - window_.frames_published;
  const double fps = dt_s > 0.0 ? static_cast<double>(frames) / dt_s : 0.0;
  LatencySnapshot latency = latency_now();
  const double p99_ms = latency.since(window_latency_).stats().p99_us / 1000.0;
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s%.1f fps, p99 %.2f ms, dropped %" PRIu64 " (total %" PRIu64 ")",
                stalled_ ? "STALLED " : "", fps, p99_ms,
                snap.frames_dropped - window_.frames_dropped, snap.frames_dropped);
  last_status_ = buf;
  notifier_.notify("STATUS=" + last_status_);
  if (log_period_ns_ > 0 && now_ns >= next_log_ns_) {
    log_line(last_status_);
    next_log_ns_ = now_ns + log_period_ns_;
  }
  window_ = snap;
  window_latency_ = std::move(latency);
  window_ns_ = now_ns;
  next_status_ns_ = now_ns + status_period_ns_;
}

void Supervisor::stopping() {
  if (state_ == State::kStopping) return;
  state_ = State::kStopping;
  notifier_.notify("STOPPING=1");
}

}  // namespace mocap::service
