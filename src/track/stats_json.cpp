#include "track/stats_json.h"

#include <cstdio>

namespace mocap {

std::vector<std::pair<std::string, std::uint64_t>> collect_counters(const FrameProcessor& p) {
  std::vector<std::pair<std::string, std::uint64_t>> c;
  for (int cam = 0; cam < p.camera_count(); ++cam) {
    const detect::DetectorCounters& d = p.detector_counters(cam);
    const std::string k = "detect_cam" + std::to_string(cam) + "_";
    c.emplace_back(k + "frames", d.frames);
    c.emplace_back(k + "frames_invalid", d.frames_invalid);
    c.emplace_back(k + "frames_overflow", d.frames_overflow);
    c.emplace_back(k + "blobs_dropped", d.blobs_dropped);
    c.emplace_back(k + "rejected_small", d.rejected_small);
    c.emplace_back(k + "rejected_large", d.rejected_large);
    c.emplace_back(k + "rejected_elongated", d.rejected_elongated);
    c.emplace_back(k + "merged", d.merged);
    c.emplace_back(k + "splits", d.splits);
  }
  const StereoCounters& s = p.stereo_counters();
  c.emplace_back("stereo_frames", s.frames);
  c.emplace_back("stereo_candidates", s.candidates);
  c.emplace_back("stereo_ambiguous", s.ambiguous);
  c.emplace_back("stereo_rejected_reproj", s.rejected_reproj);
  c.emplace_back("stereo_candidate_overflow", s.candidate_overflow);
  c.emplace_back("stereo_points_overflow", s.points_overflow[0] + s.points_overflow[1]);
  if (p.camera_count() > 2) {
    const MultiViewCounters& m = p.multiview_counters();
    c.emplace_back("multiview_views_added", m.views_added);
    c.emplace_back("multiview_views_dropped", m.views_dropped);
    c.emplace_back("multiview_merged", m.merged);
    c.emplace_back("multiview_unfit_views", m.unfit_views);
    c.emplace_back("multiview_unfit_pairings", m.unfit_pairings);
    c.emplace_back("multiview_ghosts_rejected", m.ghosts_rejected);
    c.emplace_back("multiview_ambiguous", m.ambiguous);
    c.emplace_back("multiview_hypothesis_overflow", m.hypothesis_overflow);
    c.emplace_back("multiview_point_overflow", m.point_overflow);
    c.emplace_back("multiview_shared_views_split", m.shared_views_split);
  }
  const IdentifyCounters& i = p.identify_counters();
  c.emplace_back("identify_bodies_found", i.bodies_found);
  c.emplace_back("identify_full_searches", i.full_searches);
  c.emplace_back("identify_warm_accepted", i.warm_accepted);
  c.emplace_back("identify_warm_fallbacks", i.warm_fallbacks);
  c.emplace_back("identify_velocity_rejects", i.velocity_rejects);
  c.emplace_back("identify_jump_reboots", i.jump_reboots);
  c.emplace_back("identify_point_overflow", i.point_overflow);
  c.emplace_back("identify_node_limit_hits", i.node_limit_hits);
  if (const ChainCounters* k = p.chain_counters()) {
    c.emplace_back("chain_attempts", k->attempts);
    c.emplace_back("chain_joints_solved", k->joints_solved);
    c.emplace_back("chain_too_few_labels", k->too_few_labels);
    c.emplace_back("chain_ambiguous_labels", k->ambiguous_labels);
    c.emplace_back("chain_chi2_drops", k->chi2_drops);
    c.emplace_back("chain_chi2_rejects", k->chi2_rejects);
    c.emplace_back("chain_uncertain_rejects", k->uncertain_rejects);
    c.emplace_back("chain_node_limit_hits", k->node_limit_hits);
    for (std::size_t j = 0; j < p.model().joints.size() && j < k->joint_poses.size(); ++j) {
      const std::string key = "coverage_" + p.model().joints[j].name + "_";
      c.emplace_back(key + "poses", k->joint_poses[j]);
      c.emplace_back(key + "chain", k->joint_chain[j]);
    }
  }
  return c;
}

std::string stats_to_json(const TrackStats& stats) {
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof buf, "{\"frames\": %lld,\n \"stages\": {",
                static_cast<long long>(stats.frames));
  out += buf;
  const std::pair<const char*, const LatencyHistogram*> stages[] = {
      {"detect", &stats.detect},
      {"triangulate", &stats.triangulate},
      {"identify", &stats.identify},
      {"angles", &stats.angles},
      {"frame", &stats.frame}};
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
