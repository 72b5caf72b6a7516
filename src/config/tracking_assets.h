// Design: which rig, targets and joint model `mocap run` tracks with, resolved the same
// way at load time (to validate a configuration completely) and at start (to build the
// tracker): a file named in the configuration wins; otherwise the backend's own assets
// (the sim scene's rig, targets and true model; the replay recording's rig.yaml);
// hardware backends need rig and targets in the file, the model is optional (without
// one, poses are tracked but no joint angles are published).
#pragma once

#include <optional>

#include "config/run_config.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/simulate.h"

namespace mocap::config {

struct TrackingAssets {
  Rig rig;
  TargetSet targets;
  std::optional<JointModel> model;
};

// The options the sim backend renders its loop with (scene, loop length, rate).
sim::SimOptions sim_options(const RunConfig& cfg);

// `native_*` are the backend's own assets, each may be null. Errors name the
// configuration key ("FILE: rig: required by the v4l2 backend") or the loaded file.
// With targets_required = false (`mocap record`, `mocap preview`: cameras before any
// target exists), a backend without targets gets an empty target set: the tracker then
// reports 3D points only.
Expected<TrackingAssets> load_tracking_assets(const RunConfig& cfg, const Rig* native_rig,
                                              const TargetSet* native_targets,
                                              const JointModel* native_model,
                                              bool targets_required = true);

// The compiled capacities the assets must fit (docs/formats.md, "Capacities"): at most
// kMaxBodies bodies of at most kMaxMarkers markers each, and at most kMaxBodies joints
// (every one fits the live message's client::kMaxJoints). One line naming the
// configuration, its key and the file: "FILE: targets: T.yaml: bodies: 33 bodies, at
// most 32 (the compiled capacity kMaxBodies)".
Expected<void> check_capacities(const std::string& file, const TrackingAssets& assets,
                                const std::string& targets_file, const std::string& model_file);

// Load-time check: resolves the assets (building the sim scene or opening the replay
// recording, both cheap), checks the configured camera sizes against the rig and
// builds the tracker once with the configured thresholds.
Expected<void> check_tracking_assets(const RunConfig& cfg, bool targets_required = true);

}  // namespace mocap::config
