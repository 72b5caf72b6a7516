#include "discover/discover.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

#include "discover/body_builder.h"
#include "discover/body_union.h"
#include "discover/point_tracker.h"
#include "discover/rigid_groups.h"
#include "discover/topology.h"
#include "identify/ambiguity.h"
#include "identify/target_model.h"
#include "track/calibration_input.h"

namespace mocap::discover {
namespace {

double seconds_since(std::chrono::steady_clock::time_point& t0) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - t0).count();
  t0 = now;
  return s;
}

std::string format_mm(const Vec3& X) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", X.x(), X.y(), X.z());
  return buf;
}

void warn_unplaced(const std::vector<PointTrack>& tracks, const std::vector<int>& unplaced,
                   const std::vector<FramePoints>& frames, std::vector<std::string>& warnings) {
  if (unplaced.empty()) return;
  std::vector<int> order = unplaced;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return tracks[static_cast<std::size_t>(a)].seen > tracks[static_cast<std::size_t>(b)].seen;
  });
  warnings.push_back(
      std::to_string(unplaced.size()) +
      " point track(s) seen long enough could not be placed in a body (too rarely seen "
      "with moving markers, or fitting two bodies); they are left out");
  for (std::size_t i = 0; i < std::min<std::size_t>(order.size(), 5); ++i) {
    const PointTrack& t = tracks[static_cast<std::size_t>(order[i])];
    const Vec3& X = t.at(t.first);
    warnings.push_back("unplaced point: seen in " + std::to_string(t.seen) + " frames (" +
                       std::to_string(frames[static_cast<std::size_t>(t.first)].frame) + ".." +
                       std::to_string(frames[static_cast<std::size_t>(t.last())].frame) +
                       ") near world " + format_mm(X));
  }
}

void warn_ambiguous(const TargetSet& targets, std::vector<std::string>& warnings) {
  IdentifyConfig cfg;
  std::vector<TargetModel> models;
  for (std::size_t b = 0; b < targets.bodies.size(); ++b) {
    auto m = make_target_model(targets.bodies[b], cfg, "targets: " + targets.bodies[b].name);
    if (!m) {
      warnings.push_back(m.error().message + " (identification would reject this target)");
      return;
    }
    models.push_back(std::move(m).value());
  }
  for (const AmbiguityFinding& f : find_ambiguities(models, cfg))
    warnings.push_back("symmetric or look-alike targets: " + f.message);
}

}  // namespace

Expected<DiscoverResult> discover_model(const PointSequence& seq, const DiscoverOptions& options,
                                        const std::string& label, const PoseSource& pose_source) {
  DiscoverOptions opt = options;
  DiscoverResult r;
  DiscoverStats& st = r.stats;
  st.frames = static_cast<int>(seq.frames.size());
  for (const FramePoints& f : seq.frames) st.points += static_cast<long long>(f.X_world_mm.size());
  if (st.frames < opt.min_frames)
    return Error{label + ": " + std::to_string(st.frames) + " frames, at least " +
                 std::to_string(opt.min_frames) + " are needed to discover bodies and joints"};
  if (st.points == 0)
    return Error{label + ": no 3D marker point in any frame (no marker seen by both cameras)"};
  auto t0 = std::chrono::steady_clock::now();

  TrackedPoints points = point_tracks(seq, opt);
  const std::vector<PointTrack> tracks = std::move(points.tracks);
  opt.point_noise_mm = points.point_noise_mm;  // the later steps' noise
  st.point_noise_mm = opt.point_noise_mm;
  st.min_covisible_frames = opt.min_covisible_frames();
  st.min_placement_frames = opt.min_placement_frames();
  st.tracks = static_cast<int>(tracks.size());
  for (const PointTrack& t : tracks) st.long_tracks += t.seen >= opt.min_track_frames ? 1 : 0;
  const std::vector<char> moving = scene_motion(seq, tracks, opt);
  st.seconds_tracking = seconds_since(t0);
  if (std::none_of(moving.begin(), moving.end(), [](char m) { return m != 0; }))
    return Error{label +
                 ": nothing moves (a static scene): record the robot moving its joints, so that "
                 "markers can be grouped into bodies and joints estimated"};

  const auto groups = group_rigid_tracks(tracks, moving, opt);
  st.clusters = static_cast<int>(groups.size());
  st.seconds_grouping = seconds_since(t0);

  BodyBuild built = build_bodies(tracks, groups, moving, opt);
  st.unplaced_tracks = static_cast<int>(built.unplaced_tracks.size());
  st.seconds_bodies = seconds_since(t0);
  if (built.bodies.empty())
    return Error{label + ": no rigid body of at least 3 markers found (" +
                 std::to_string(st.long_tracks) +
                 " point tracks of >= " + std::to_string(opt.min_track_frames) +
                 " frames): the markers must be seen while the bodies turn"};
  if (built.bodies.size() == 1)
    return Error{
        label + ": one rigid body only (" + std::to_string(built.bodies[0].markers_body.size()) +
        " markers): no joint to discover; move the robot's joints, not the robot as a whole"};

  // The tracker's poses of the bodies' targets (replacing the discovery poses).
  std::optional<kinematics::CalibrationInput> tracked;
  auto track_bodies = [&]() {
    tracked.reset();
    if (!pose_source) return;
    TargetSet provisional;
    provisional.marker_diameter_mm = opt.marker_diameter_mm;
    for (std::size_t b = 0; b < built.bodies.size(); ++b)
      provisional.bodies.push_back({"body" + std::to_string(b), built.bodies[b].markers_body});
    auto in = pose_source(provisional);
    if (in && in->frames.size() == seq.frames.size()) {
      for (std::size_t b = 0; b < built.bodies.size(); ++b)
        for (std::size_t f = 0; f < seq.frames.size(); ++f) {
          const kinematics::BodyObservation& obs = in->frames[f].bodies[b];
          built.bodies[b].found[f] = obs.found ? 1 : 0;
          if (obs.found) built.bodies[b].T_world_body[f] = obs.T_world_body;
        }
      tracked = std::move(in).value();
    } else {
      r.warnings.push_back("tracking the recording with the discovered targets failed (" +
                           (in ? std::to_string(in->frames.size()) + " frames instead of " +
                                     std::to_string(seq.frames.size())
                               : in.error().message) +
                           "); joints are estimated on the discovery poses");
    }
  };
  track_bodies();
  st.seconds_tracker = seconds_since(t0);

  TopologyResult topo = infer_topology(built.bodies, opt);
  // One body built as two: children of one parent at one joint centre that move as one
  // (body_union.h) are merged, then tracked and joined again.
  for (int round = 0; round < 2; ++round) {
    const auto split = find_split_bodies(built.bodies, topo, opt);
    if (split.empty()) break;
    st.merged_bodies += static_cast<int>(split.size());
    built.bodies = merge_bodies(std::move(built.bodies), split, opt);
    track_bodies();
    topo = infer_topology(built.bodies, opt);
  }
  st.seconds_topology = seconds_since(t0);

  // Output order and names.
  std::vector<int> new_index(built.bodies.size(), -1);
  std::vector<DiscoveredBody> ordered;
  for (int b : topo.body_order) {
    new_index[static_cast<std::size_t>(b)] = static_cast<int>(ordered.size());
    ordered.push_back(built.bodies[static_cast<std::size_t>(b)]);
  }
  r.targets.marker_diameter_mm = opt.marker_diameter_mm;
  for (std::size_t b = 0; b < ordered.size(); ++b)
    r.targets.bodies.push_back({"body" + std::to_string(b), ordered[b].markers_body});
  std::vector<char> joined(ordered.size(), 0);
  for (const JointEdge& e : topo.joints) {
    JointSpec j;
    j.parent_index = new_index[static_cast<std::size_t>(e.parent)];
    j.child_index = new_index[static_cast<std::size_t>(e.child)];
    j.parent = r.targets.bodies[static_cast<std::size_t>(j.parent_index)].name;
    j.child = r.targets.bodies[static_cast<std::size_t>(j.child_index)].name;
    j.name = j.parent + "_" + j.child;
    j.type = e.type;
    joined[static_cast<std::size_t>(j.parent_index)] =
        joined[static_cast<std::size_t>(j.child_index)] = 1;
    r.topology.joints.push_back(j);
  }
  if (tracked) {  // the tracker's observations, bodies in output order
    r.input.frames.resize(tracked->frames.size());
    for (std::size_t f = 0; f < tracked->frames.size(); ++f)
      for (int b : topo.body_order)
        r.input.frames[f].bodies.push_back(
            std::move(tracked->frames[f].bodies[static_cast<std::size_t>(b)]));
  } else {
    r.input = make_calibration_input(ordered, tracks, seq.frames.size(), opt);
  }

  warn_unplaced(tracks, built.unplaced_tracks, seq.frames, r.warnings);
  warn_ambiguous(r.targets, r.warnings);
  for (std::size_t b = 0; b < ordered.size(); ++b) {
    if (joined[b]) continue;
    std::string why;
    for (const auto& [x, y] : topo.low_motion_pairs) {
      const int other = new_index[static_cast<std::size_t>(x)] == static_cast<int>(b)
                            ? new_index[static_cast<std::size_t>(y)]
                        : new_index[static_cast<std::size_t>(y)] == static_cast<int>(b)
                            ? new_index[static_cast<std::size_t>(x)]
                            : -1;
      if (other >= 0)
        why += (why.empty() ? "" : ", ") + r.targets.bodies[static_cast<std::size_t>(other)].name;
    }
    r.warnings.push_back(
        r.targets.bodies[b].name + ": joined to no other body (listed in targets.yaml only)" +
        (why.empty() ? std::string()
                     : "; too little relative motion to determine a joint with " + why));
  }
  if (r.topology.joints.empty()) {  // the caller decides (joints.yaml needs a joint)
    st.seconds_calibration = seconds_since(t0);
    return r;
  }
  kinematics::CalibrationOptions copt;
  copt.linear = opt.linear;
  copt.refine = opt.refine;
  copt.covariance = opt.refine;
  auto cal = kinematics::calibrate_joints(r.targets, r.topology, r.input, copt);
  if (!cal) return Error{label + ": " + cal.error().message};
  r.calibration = std::move(cal).value();
  r.model = r.calibration.model;
  for (const std::string& w : r.calibration.report.warnings) r.warnings.push_back(w);
  st.seconds_calibration = seconds_since(t0);
  return r;
}

PoseSource tracker_poses(const std::string& recording,
                         std::function<void(std::int64_t, std::int64_t)> progress) {
  return [recording, progress](const TargetSet& targets) -> Expected<kinematics::CalibrationInput> {
    CalibrationCollectOptions collect;
    collect.progress = progress;
    auto collected = collect_calibration_input(recording, targets, collect);
    if (!collected) return collected.error();
    return std::move(collected->input);
  };
}

}  // namespace mocap::discover
