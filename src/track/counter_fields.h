// Design: the one table of names of the per-frame libraries' counters. The blob detector,
// the stereo triangulator, the multi-view merger, the identifier and the chain solver
// keep their counters as plain integers in a struct of their own; this header says, once,
// under which name each field is reported and how it is read. Both reports use it:
// `mocap track --stats` (track/stats_json.cpp, "counters" of stats.json) and the live
// pipeline's `mocap run --stats` and health (pipeline/stage_counters.h mirrors each table
// into atomics). A new counter costs one line here and appears in both.
//
// Reported names are <prefix><name>: detect_cam<N>_, stereo_, multiview_, identify_,
// chain_ (docs/pipeline.md lists them). read() is noexcept and allocation-free: the
// pipeline calls it on its real-time threads after every frame.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "detect/blob.h"
#include "identify/identify_types.h"
#include "stereo/multiview.h"
#include "stereo/stereo_triangulator.h"
#include "track/chain_solver.h"

namespace mocap {

template <class Source>
struct CounterField {
  const char* name;
  std::uint64_t (*read)(const Source&) noexcept;
};

// Appends (prefix + name, value) for every field of `table` read from `source`.
template <class Source, std::size_t N>
void append_counters(std::vector<std::pair<std::string, std::uint64_t>>& out,
                     std::string_view prefix, const Source& source,
                     const std::array<CounterField<Source>, N>& table) {
  for (const CounterField<Source>& f : table)
    out.emplace_back(std::string(prefix) + f.name, f.read(source));
}

// A table entry reading field `f` of a `S` (captureless lambda -> function pointer).
// clang-format off
#define MOCAP_COUNTER_FIELD(S, f) \
  CounterField<S> { #f, [](const S& s) noexcept -> std::uint64_t { return s.f; } }
// clang-format on

// Per camera, reported as detect_cam<N>_<name>.
inline constexpr std::array<CounterField<detect::DetectorCounters>, 13> kDetectorFields = {{
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, frames),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, frames_invalid),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, frames_no_contrast),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, frames_overflow),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, runs_overflow),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, blobs_dropped),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, components),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, rejected_small),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, rejected_large),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, rejected_elongated),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, rejected_border),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, merged),
    MOCAP_COUNTER_FIELD(detect::DetectorCounters, splits),
}};
// Index of frames_overflow in kDetectorFields (PipelineHealth::detect_overflow_frames).
inline constexpr std::size_t kDetectorFramesOverflow = 3;
static_assert(std::string_view(kDetectorFields[kDetectorFramesOverflow].name) == "frames_overflow");

// Reported as stereo_<name>: the sum over the rig's camera pairs (StereoCounters::+=).
// points_in_cam0 / _cam1 count the blobs given to each pair's first / second camera,
// summed over the pairs: cameras 0 and 1 with two cameras; with more, the per-camera
// blob counts are the detectors' (detect_cam<N>_*).
inline constexpr std::array<CounterField<StereoCounters>, 15> kStereoFields = {{
    MOCAP_COUNTER_FIELD(StereoCounters, frames),
    {"points_in_cam0",
     [](const StereoCounters& s) noexcept -> std::uint64_t { return s.points_in[0]; }},
    {"points_in_cam1",
     [](const StereoCounters& s) noexcept -> std::uint64_t { return s.points_in[1]; }},
    {"points_overflow",
     [](const StereoCounters& s) noexcept -> std::uint64_t {
       return s.points_overflow[0] + s.points_overflow[1];
     }},
    {"undistort_failed",
     [](const StereoCounters& s) noexcept -> std::uint64_t {
       return s.undistort_failed[0] + s.undistort_failed[1];
     }},
    MOCAP_COUNTER_FIELD(StereoCounters, pairs_in_tolerance),
    MOCAP_COUNTER_FIELD(StereoCounters, settled_blobs),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_degenerate),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_cheirality),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_depth),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_reproj),
    MOCAP_COUNTER_FIELD(StereoCounters, candidates),
    MOCAP_COUNTER_FIELD(StereoCounters, ambiguous),
    MOCAP_COUNTER_FIELD(StereoCounters, candidate_overflow),
    MOCAP_COUNTER_FIELD(StereoCounters, bad_input),
}};

// Reported as multiview_<name>, with three or more cameras.
inline constexpr std::array<CounterField<MultiViewCounters>, 16> kMultiViewFields = {{
    MOCAP_COUNTER_FIELD(MultiViewCounters, frames),
    MOCAP_COUNTER_FIELD(MultiViewCounters, hypotheses),
    MOCAP_COUNTER_FIELD(MultiViewCounters, hypothesis_overflow),
    MOCAP_COUNTER_FIELD(MultiViewCounters, views_added),
    MOCAP_COUNTER_FIELD(MultiViewCounters, views_dropped),
    MOCAP_COUNTER_FIELD(MultiViewCounters, merged),
    MOCAP_COUNTER_FIELD(MultiViewCounters, unfit_views),
    MOCAP_COUNTER_FIELD(MultiViewCounters, unfit_pairings),
    MOCAP_COUNTER_FIELD(MultiViewCounters, shared_views_split),
    MOCAP_COUNTER_FIELD(MultiViewCounters, ghosts_rejected),
    MOCAP_COUNTER_FIELD(MultiViewCounters, ambiguous),
    MOCAP_COUNTER_FIELD(MultiViewCounters, points),
    MOCAP_COUNTER_FIELD(MultiViewCounters, point_overflow),
    MOCAP_COUNTER_FIELD(MultiViewCounters, blob_overflow),
    MOCAP_COUNTER_FIELD(MultiViewCounters, settled),
    MOCAP_COUNTER_FIELD(MultiViewCounters, undistorted_late),
}};

// Reported as identify_<name>.
inline constexpr std::array<CounterField<IdentifyCounters>, 18> kIdentifyFields = {{
    MOCAP_COUNTER_FIELD(IdentifyCounters, frames),
    MOCAP_COUNTER_FIELD(IdentifyCounters, bodies_found),
    MOCAP_COUNTER_FIELD(IdentifyCounters, full_searches),
    MOCAP_COUNTER_FIELD(IdentifyCounters, warm_accepted),
    MOCAP_COUNTER_FIELD(IdentifyCounters, warm_fallbacks),
    MOCAP_COUNTER_FIELD(IdentifyCounters, conflict_researches),
    MOCAP_COUNTER_FIELD(IdentifyCounters, velocity_rejects),
    MOCAP_COUNTER_FIELD(IdentifyCounters, jump_reboots),
    MOCAP_COUNTER_FIELD(IdentifyCounters, point_overflow),
    MOCAP_COUNTER_FIELD(IdentifyCounters, invalid_points),
    MOCAP_COUNTER_FIELD(IdentifyCounters, node_limit_hits),
    MOCAP_COUNTER_FIELD(IdentifyCounters, bad_timestamps),
    MOCAP_COUNTER_FIELD(IdentifyCounters, ambiguous_rejects),
    MOCAP_COUNTER_FIELD(IdentifyCounters, outlier_markers),
    MOCAP_COUNTER_FIELD(IdentifyCounters, consistency_rejects),
    MOCAP_COUNTER_FIELD(IdentifyCounters, partial_excluded),
    MOCAP_COUNTER_FIELD(IdentifyCounters, partial_rejects),
    MOCAP_COUNTER_FIELD(IdentifyCounters, continuity_resolved),
}};

// Reported as chain_<name>, with a kinematic model.
inline constexpr std::array<CounterField<ChainCounters>, 11> kChainFields = {{
    MOCAP_COUNTER_FIELD(ChainCounters, frames),
    MOCAP_COUNTER_FIELD(ChainCounters, attempts),
    MOCAP_COUNTER_FIELD(ChainCounters, joints_solved),
    MOCAP_COUNTER_FIELD(ChainCounters, too_few_labels),
    MOCAP_COUNTER_FIELD(ChainCounters, ambiguous_labels),
    MOCAP_COUNTER_FIELD(ChainCounters, chi2_drops),
    MOCAP_COUNTER_FIELD(ChainCounters, chi2_rejects),
    MOCAP_COUNTER_FIELD(ChainCounters, uncertain_rejects),
    MOCAP_COUNTER_FIELD(ChainCounters, node_limit_hits),
    MOCAP_COUNTER_FIELD(ChainCounters, pose_refits),
    MOCAP_COUNTER_FIELD(ChainCounters, pose_rejects),
}};
#undef MOCAP_COUNTER_FIELD

// Coverage per joint (model order): entry 2j counts the frames joint j was valid from
// the two poses, 2j+1 through the chain; reported as coverage_<joint>_poses / _chain.
template <std::size_t... I>
constexpr std::array<CounterField<ChainCounters>, 2 * sizeof...(I)> make_coverage_fields(
    std::index_sequence<I...>) noexcept {
  std::array<CounterField<ChainCounters>, 2 * sizeof...(I)> f{};
  ((f[2 * I] = {"poses",
                [](const ChainCounters& s) noexcept -> std::uint64_t { return s.joint_poses[I]; }},
    f[2 * I + 1] = {"chain",
                    [](const ChainCounters& s) noexcept -> std::uint64_t {
                      return s.joint_chain[I];
                    }}),
   ...);
  return f;
}
inline constexpr auto kCoverageFields = make_coverage_fields(
    std::make_index_sequence<std::tuple_size_v<decltype(ChainCounters::joint_poses)>>{});

}  // namespace mocap
