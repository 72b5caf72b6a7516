#include "track/stats_json.h"

#include <cstdio>

namespace mocap {

namespace {

using Counters = std::vector<std::pair<std::string, std::uint64_t>>;

// One stats.json key of a counter struct: the key without its prefix and the member.
template <class S>
struct StatsField {
  const char* key;
  std::uint64_t S::*member;
};

// The counters of stats.json (keys are public: ../shared/spec/interfaces.md), in output
// order; a new counter costs one line here.
constexpr StatsField<detect::DetectorCounters> kDetectFields[] = {
    {"frames", &detect::DetectorCounters::frames},
    {"frames_invalid", &detect::DetectorCounters::frames_invalid},
    {"frames_overflow", &detect::DetectorCounters::frames_overflow},
    {"blobs_dropped", &detect::DetectorCounters::blobs_dropped},
    {"rejected_small", &detect::DetectorCounters::rejected_small},
    {"rejected_large", &detect::DetectorCounters::rejected_large},
    {"rejected_elongated", &detect::DetectorCounters::rejected_elongated},
    {"merged", &detect::DetectorCounters::merged},
    {"splits", &detect::DetectorCounters::splits},
};
constexpr StatsField<StereoCounters> kStereoFields[] = {
    {"frames", &StereoCounters::frames},
    {"candidates", &StereoCounters::candidates},
    {"ambiguous", &StereoCounters::ambiguous},
    {"rejected_reproj", &StereoCounters::rejected_reproj},
    {"candidate_overflow", &StereoCounters::candidate_overflow},
};
constexpr StatsField<MultiViewCounters> kMultiViewFields[] = {
    {"views_added", &MultiViewCounters::views_added},
    {"views_dropped", &MultiViewCounters::views_dropped},
    {"merged", &MultiViewCounters::merged},
    {"unfit_views", &MultiViewCounters::unfit_views},
    {"unfit_pairings", &MultiViewCounters::unfit_pairings},
    {"ghosts_rejected", &MultiViewCounters::ghosts_rejected},
    {"ambiguous", &MultiViewCounters::ambiguous},
    {"hypothesis_overflow", &MultiViewCounters::hypothesis_overflow},
    {"point_overflow", &MultiViewCounters::point_overflow},
    {"shared_views_split", &MultiViewCounters::shared_views_split},
};
constexpr StatsField<IdentifyCounters> kIdentifyFields[] = {
    {"bodies_found", &IdentifyCounters::bodies_found},
    {"full_searches", &IdentifyCounters::full_searches},
    {"warm_accepted", &IdentifyCounters::warm_accepted},
    {"warm_fallbacks", &IdentifyCounters::warm_fallbacks},
    {"velocity_rejects", &IdentifyCounters::velocity_rejects},
    {"jump_reboots", &IdentifyCounters::jump_reboots},
    {"point_overflow", &IdentifyCounters::point_overflow},
    {"node_limit_hits", &IdentifyCounters::node_limit_hits},
};
constexpr StatsField<ChainCounters> kChainFields[] = {
    {"attempts", &ChainCounters::attempts},
    {"joints_solved", &ChainCounters::joints_solved},
    {"too_few_labels", &ChainCounters::too_few_labels},
    {"ambiguous_labels", &ChainCounters::ambiguous_labels},
    {"chi2_drops", &ChainCounters::chi2_drops},
    {"chi2_rejects", &ChainCounters::chi2_rejects},
    {"uncertain_rejects", &ChainCounters::uncertain_rejects},
    {"node_limit_hits", &ChainCounters::node_limit_hits},
};

template <class S, std::size_t N>
void add_fields(Counters& out, const std::string& prefix, const S& counters,
                const StatsField<S> (&fields)[N]) {
  for (const StatsField<S>& f : fields) out.emplace_back(prefix + f.key, counters.*f.member);
}

}  // namespace

Counters collect_counters(const FrameProcessor& p) {
  Counters c;
  for (int cam = 0; cam < p.camera_count(); ++cam) {
    add_fields(c, "detect_cam" + std::to_string(cam) + "_", p.detector_counters(cam),
               kDetectFields);
  }
  const StereoCounters& s = p.stereo_counters();
  add_fields(c, "stereo_", s, kStereoFields);
  c.emplace_back("stereo_points_overflow", s.points_overflow[0] + s.points_overflow[1]);
  if (p.camera_count() > 2) add_fields(c, "multiview_", p.multiview_counters(), kMultiViewFields);
  add_fields(c, "identify_", p.identify_counters(), kIdentifyFields);
  if (const ChainCounters* k = p.chain_counters()) {
    add_fields(c, "chain_", *k, kChainFields);
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
