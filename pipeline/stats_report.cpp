// Design: see stats_report.h. Plain snprintf formatting; the JSON keys are fixed
// identifiers (no escaping needed).
#include "pipeline/stats_report.h"

#include <cstdio>
#include <string>
#include <vector>

namespace mocap::pipeline {
namespace {

// Per-joint coverage read back from the coverage_<joint>_poses/_chain counters, as
// shares of the frames chain tracking processed (chain_frames).
struct JointCoverage {
  std::string joint;
  double poses = 0.0, chain = 0.0;
};

std::vector<JointCoverage> coverage_of(const PipelineStats& s) {
  std::uint64_t frames = 0;
  for (const auto& [name, v] : s.counters)
    if (name == "chain_frames") frames = v;
  std::vector<JointCoverage> out;
  if (frames == 0) return out;
  const std::string prefix = "coverage_", poses = "_poses";
  for (const auto& [name, v] : s.counters) {
    if (name.rfind(prefix, 0) != 0 || name.size() <= prefix.size() + poses.size() ||
        name.compare(name.size() - poses.size(), poses.size(), poses) != 0)
      continue;
    JointCoverage c;
    c.joint = name.substr(prefix.size(), name.size() - prefix.size() - poses.size());
    c.poses = static_cast<double>(v) / static_cast<double>(frames);
    for (const auto& [n2, v2] : s.counters)
      if (n2 == prefix + c.joint + "_chain")
        c.chain = static_cast<double>(v2) / static_cast<double>(frames);
    out.push_back(c);
  }
  return out;
}

}  // namespace

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
  const std::vector<JointCoverage> cov = coverage_of(s);
  if (!cov.empty()) {
    out += "joint coverage (share of processed frames)   valid    poses    chain\n";
    for (const JointCoverage& c : cov) {
      std::snprintf(line, sizeof line, "  %-40s %6.1f%% %7.1f%% %7.1f%%\n", c.joint.c_str(),
                    100.0 * (c.poses + c.chain), 100.0 * c.poses, 100.0 * c.chain);
      out += line;
    }
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
  // Per camera values joined by '/' (one entry per camera of the rig).
  auto per_camera = [&](auto value) {
    std::string v;
    for (int c = 0; c < h.camera_count; ++c) {
      if (c > 0) v += '/';
      v += std::to_string(value(static_cast<std::size_t>(c)));
    }
    return v;
  };
  const std::string silent = per_camera([&](std::size_t c) { return h.camera_silent_ms[c]; });
  const std::string overflow =
      per_camera([&](std::size_t c) { return h.detect_overflow_frames[c]; });
  const std::string steps = per_camera([&](std::size_t c) { return h.timestamp_steps[c]; });
  char line[480];
  std::snprintf(line, sizeof line,
                "t=%.1fs fps=%.1f e2e(last %.1fs, %llu) p50=%.0f p99=%.0f p99.9=%.0f max=%.0f us "
                "published=%llu dropped=%llu cam silent=%s ms blob overflow=%s "
                "clock steps=%s outputs failed/dropped=%llu/%llu",
                elapsed_s, h.fps, interval_s, static_cast<unsigned long long>(e2e.count),
                e2e.p50_us, e2e.p99_us, e2e.p999_us, e2e.max_us,
                static_cast<unsigned long long>(h.frames_published),
                static_cast<unsigned long long>(h.frames_dropped), silent.c_str(), overflow.c_str(),
                steps.c_str(), static_cast<unsigned long long>(h.output_failures),
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
  if (!s.gauges.empty()) {
    out += "\n  },\n  \"gauges\": {";
    for (std::size_t i = 0; i < s.gauges.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s\n    \"%s\": %.3f", i == 0 ? "" : ",",
                    s.gauges[i].first.c_str(), s.gauges[i].second);
      out += buf;
    }
  }
  out += "\n  },\n  \"coverage\": {";
  const std::vector<JointCoverage> cov = coverage_of(s);
  for (std::size_t i = 0; i < cov.size(); ++i) {
    std::snprintf(buf, sizeof buf,
                  "%s\n    \"%s\": {\"valid\": %.5f, \"poses\": %.5f, \"chain\": %.5f}",
                  i == 0 ? "" : ",", cov[i].joint.c_str(), cov[i].poses + cov[i].chain,
                  cov[i].poses, cov[i].chain);
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
