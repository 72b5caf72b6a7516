// Design: see stats_report.h. Plain snprintf formatting; the JSON keys are fixed
// identifiers (no escaping needed).
#include "pipeline/stats_report.h"

#include <cstdio>

namespace mocap::pipeline {

std::string format_pipeline_stats(const PipelineStats& s) {
  std::string out;
  char line[320];
  std::snprintf(line, sizeof line, "run: %.2f s, %llu frames triggered, %llu published, %.1f fps\n",
                s.duration_s, static_cast<unsigned long long>(s.triggered),
                static_cast<unsigned long long>(s.published), s.fps);
  out += line;
  out += "latency from the trigger (us)      count      p50      p99    p99.9      max\n";
  for (const auto& [name, l] : s.latency) {
    const char* label = name == "publish" ? "publish (end to end)" : name.c_str();
    std::snprintf(line, sizeof line, "  %-30s %8llu %8.0f %8.0f %8.0f %8.0f\n", label,
                  static_cast<unsigned long long>(l.count), l.p50_us, l.p99_us, l.p999_us,
                  l.max_us);
    out += line;
  }
  out += "counters:";
  int n = 0;
  for (const auto& [name, v] : s.counters) {
    std::snprintf(line, sizeof line, "%s %s=%llu", (n++ % 4 == 0) ? "\n " : "", name.c_str(),
                  static_cast<unsigned long long>(v));
    out += line;
  }
  out += "\n";
  return out;
}

std::string format_progress_line(double elapsed_s, double interval_s, const LatencyStats& e2e,
                                 const PipelineHealth& h) {
  char line[400];
  std::snprintf(
      line, sizeof line,
      "t=%.1fs fps=%.1f e2e(last %.1fs, %llu) p50=%.0f p99=%.0f p99.9=%.0f max=%.0f us "
      "published=%llu dropped=%llu cam silent=%lld/%lld ms blob overflow=%llu/%llu "
      "clock steps=%llu/%llu outputs failed/dropped=%llu/%llu",
      elapsed_s, h.fps, interval_s, static_cast<unsigned long long>(e2e.count), e2e.p50_us,
      e2e.p99_us, e2e.p999_us, e2e.max_us, static_cast<unsigned long long>(h.frames_published),
      static_cast<unsigned long long>(h.frames_dropped),
      static_cast<long long>(h.camera_silent_ms[0]), static_cast<long long>(h.camera_silent_ms[1]),
      static_cast<unsigned long long>(h.detect_overflow_frames[0]),
      static_cast<unsigned long long>(h.detect_overflow_frames[1]),
      static_cast<unsigned long long>(h.timestamp_steps[0]),
      static_cast<unsigned long long>(h.timestamp_steps[1]),
      static_cast<unsigned long long>(h.output_failures),
      static_cast<unsigned long long>(h.output_dropped));
  return line;
}

std::string pipeline_stats_json(const PipelineStats& s) {
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "{\n  \"frames\": %llu,\n  \"triggered\": %llu,\n  \"published\": %llu,\n"
                "  \"duration_s\": %.3f,\n  \"fps\": %.2f,\n  \"stages\": {",
                static_cast<unsigned long long>(s.published),
                static_cast<unsigned long long>(s.triggered),
                static_cast<unsigned long long>(s.published), s.duration_s, s.fps);
  out += buf;
  for (std::size_t i = 0; i < s.latency.size(); ++i) {
    const LatencyStats& l = s.latency[i].second;
    std::snprintf(buf, sizeof buf,
                  "%s\n    \"%s\": {\"count\": %llu, \"p50_us\": %.1f, \"p99_us\": %.1f, "
                  "\"p999_us\": %.1f, \"max_us\": %.1f, \"mean_us\": %.1f}",
                  i == 0 ? "" : ",", s.latency[i].first.c_str(),
                  static_cast<unsigned long long>(l.count), l.p50_us, l.p99_us, l.p999_us, l.max_us,
                  l.mean_us);
    out += buf;
  }
  out += "\n  },\n  \"counters\": {";
  for (std::size_t i = 0; i < s.counters.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s\n    \"%s\": %llu", i == 0 ? "" : ",",
                  s.counters[i].first.c_str(),
                  static_cast<unsigned long long>(s.counters[i].second));
    out += buf;
  }
  out += "\n  }\n}\n";
  return out;
}

Expected<void> write_pipeline_stats_json(const std::string& path, const PipelineStats& s) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return make_error(path, "", "cannot open for writing");
  const std::string text = pipeline_stats_json(s);
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) return make_error(path, "", "write failed");
  return {};
}

}  // namespace mocap::pipeline
