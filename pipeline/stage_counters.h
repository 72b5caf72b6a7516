// Design: how the pipeline reports the counters of the per-frame libraries. The blob
// detector, the stereo triangulator and the identifier keep their counters as plain
// integers (detect::DetectorCounters, StereoCounters, IdentifyCounters) that only the
// thread running them may touch. After every frame, the stage thread that owns such a
// library republishes them into a CounterMirror: one std::atomic<std::uint64_t> per
// reported field, stored relaxed by that single writer and loaded relaxed by any reader
// (health(), stats(), a status line). Each value is untorn and at most one frame old;
// like every other pipeline counter, the values are not a snapshot of one instant.
// The field tables below name each reported counter (the names of `mocap track --stats`
// where both report it; docs/pipeline.md lists them) and read it from the library's
// struct. publish() is noexcept and allocation-free (a few ns per field and frame).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>

#include "detect/blob.h"
#include "identify/identify_types.h"
#include "stereo/stereo_triangulator.h"
#include "track/chain_solver.h"

namespace mocap::pipeline {

template <class Source>
struct CounterField {
  const char* name;
  std::uint64_t (*read)(const Source&) noexcept;
};

template <class Source, std::size_t N>
class CounterMirror {
 public:
  using Fields = std::array<CounterField<Source>, N>;

  // The owning stage thread only (the one that runs the library).
  void publish(const Fields& fields, const Source& source) noexcept {
    for (std::size_t i = 0; i < N; ++i) {
      // relaxed: a single writer; readers only need an untorn, recent tally, and no other
      // memory is published through these values.
      values_[i].store(fields[i].read(source), std::memory_order_relaxed);
    }
  }
  // Any thread.
  std::uint64_t get(std::size_t i) const noexcept {
    return values_[i].load(std::memory_order_relaxed);  // relaxed: see publish()
  }
  static constexpr std::size_t size() noexcept { return N; }

 private:
  std::array<std::atomic<std::uint64_t>, N> values_{};
};

// A table entry reading field `f` of a `S` (captureless lambda -> function pointer).
// clang-format off
#define MOCAP_COUNTER_FIELD(S, f) \
  CounterField<S> { #f, [](const S& s) noexcept -> std::uint64_t { return s.f; } }
// clang-format on

// Per camera, reported as detect_camN_<name>.
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

// Reported as stereo_<name>.
inline constexpr std::array<CounterField<StereoCounters>, 14> kStereoFields = {{
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
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_degenerate),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_cheirality),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_depth),
    MOCAP_COUNTER_FIELD(StereoCounters, rejected_reproj),
    MOCAP_COUNTER_FIELD(StereoCounters, candidates),
    MOCAP_COUNTER_FIELD(StereoCounters, ambiguous),
    MOCAP_COUNTER_FIELD(StereoCounters, candidate_overflow),
    MOCAP_COUNTER_FIELD(StereoCounters, bad_input),
}};

// Reported as identify_<name>.
inline constexpr std::array<CounterField<IdentifyCounters>, 17> kIdentifyFields = {{
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
}};

// Reported as chain_<name>.
inline constexpr std::array<CounterField<ChainCounters>, 9> kChainFields = {{
    MOCAP_COUNTER_FIELD(ChainCounters, frames),
    MOCAP_COUNTER_FIELD(ChainCounters, attempts),
    MOCAP_COUNTER_FIELD(ChainCounters, joints_solved),
    MOCAP_COUNTER_FIELD(ChainCounters, too_few_labels),
    MOCAP_COUNTER_FIELD(ChainCounters, ambiguous_labels),
    MOCAP_COUNTER_FIELD(ChainCounters, chi2_drops),
    MOCAP_COUNTER_FIELD(ChainCounters, chi2_rejects),
    MOCAP_COUNTER_FIELD(ChainCounters, uncertain_rejects),
    MOCAP_COUNTER_FIELD(ChainCounters, node_limit_hits),
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

using DetectorMirror = CounterMirror<detect::DetectorCounters, kDetectorFields.size()>;
using StereoMirror = CounterMirror<StereoCounters, kStereoFields.size()>;
using IdentifyMirror = CounterMirror<IdentifyCounters, kIdentifyFields.size()>;
using ChainMirror = CounterMirror<ChainCounters, kChainFields.size()>;
using CoverageMirror = CounterMirror<ChainCounters, kCoverageFields.size()>;

}  // namespace mocap::pipeline
