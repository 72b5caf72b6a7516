#include "track/stats_json.h"

#include <cstdio>

#include "track/counter_fields.h"

namespace mocap {

using Counters = std::vector<std::pair<std::string, std::uint64_t>>;

Counters collect_counters(const FrameProcessor& p) {
  Counters c;
  for (int cam = 0; cam < p.camera_count(); ++cam)
    append_counters(c, "detect_cam" + std::to_string(cam) + "_", p.detector_counters(cam),
                    kDetectorFields);
  append_counters(c, "stereo_", p.stereo_counters(), kStereoFields);
  if (p.camera_count() > 2)
    append_counters(c, "multiview_", p.multiview_counters(), kMultiViewFields);
  append_counters(c, "identify_", p.identify_counters(), kIdentifyFields);
  if (const ChainCounters* k = p.chain_counters()) {
    append_counters(c, "chain_", *k, kChainFields);
    for (std::size_t j = 0; j < p.model().joints.size() && 2 * j + 1 < kCoverageFields.size();
         ++j) {
      const std::string key = "coverage_" + p.model().joints[j].name + "_";
      c.emplace_back(key + kCoverageFields[2 * j].name, kCoverageFields[2 * j].read(*k));
      c.emplace_back(key + kCoverageFields[2 * j + 1].name, kCoverageFields[2 * j + 1].read(*k));
    }
  }
  return c;
}

std::string stats_to_json(const TrackStats& stats) {
  std::string out;
  char buf[256];
  // "percentiles": "exact" (nearest rank over every frame) or "histogram" (a run longer
  // than LatencySamples keeps: at most 1/64 above).
  std::snprintf(buf, sizeof buf, "{\"frames\": %lld,\n \"percentiles\": \"%s\",\n \"stages\": {",
                static_cast<long long>(stats.frames), stats.frame.exact() ? "exact" : "histogram");
  out += buf;
  const std::pair<const char*, const LatencySamples*> stages[] = {
      {"load", &stats.load},         {"detect", &stats.detect}, {"triangulate", &stats.triangulate},
      {"identify", &stats.identify}, {"angles", &stats.angles}, {"frame", &stats.frame}};
  bool first = true;
  for (const auto& [name, rec] : stages) {
    const LatencyStats s = rec->stats();
    std::snprintf(
        buf, sizeof buf,
        "%s\n   \"%s\": {\"p50_us\": %.3f, \"p99_us\": %.3f, \"max_us\": %.3f, \"mean_us\": %.3f}",
        first ? "" : ",", name, s.p50_us, s.p99_us, s.max_us, s.mean_us);
    out += buf;
    first = false;
  }
  out += "},\n \"counters\": {";
  first = true;
  for (const auto& [name, value] : stats.counters) {
    std::snprintf(buf, sizeof buf, "%s\n   \"%s\": %llu", first ? "" : ",", name.c_str(),
                  static_cast<unsigned long long>(value));
    out += buf;
    first = false;
  }
  out += "}}\n";
  return out;
}

Expected<void> write_stats_json(const std::string& path, const TrackStats& stats) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return make_error(path, "", "cannot open for writing");
  const std::string json = stats_to_json(stats);
  const bool ok = std::fwrite(json.data(), 1, json.size(), f) == json.size();
  if (std::fclose(f) != 0 || !ok) return make_error(path, "", "write failed");
  return {};
}

}  // namespace mocap
