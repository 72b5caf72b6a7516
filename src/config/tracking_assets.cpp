// Design: see tracking_assets.h.
#include "config/tracking_assets.h"

#include <string>
#include <vector>

#include "client/joints_message.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "identify/identify_types.h"
#include "track/frame_processor.h"

namespace mocap::config {

sim::SimOptions sim_options(const RunConfig& cfg) {
  sim::SimOptions so;
  so.frames = cfg.sim.loop_frames;
  so.cameras = static_cast<int>(cfg.cameras.size());
  so.rig_path = cfg.sim.rig_path;  // empty: the built-in cameras
  so.scene = cfg.sim.scene;
  so.fps = cfg.pipeline.trigger_rate_hz;
  return so;
}

Expected<TrackingAssets> load_tracking_assets(const RunConfig& cfg, const Rig* native_rig,
                                              const TargetSet* native_targets,
                                              const JointModel* native_model,
                                              bool targets_required) {
  const std::string file = cfg.path.empty() ? std::string("mocap run") : cfg.path;
  const char* backend = to_string(cfg.cameras[0].backend);
  TrackingAssets a;
  if (!cfg.rig_path.empty()) {
    auto rig = load_rig(cfg.rig_path);
    if (!rig) return make_error(file, "rig", rig.error().message);
    a.rig = std::move(rig).value();
  } else if (native_rig != nullptr) {
    a.rig = *native_rig;
  } else {
    return make_error(file, "rig", std::string("required by the ") + backend + " backend");
  }
  if (!cfg.targets_path.empty()) {
    auto targets = load_targets(cfg.targets_path);
    if (!targets) return make_error(file, "targets", targets.error().message);
    a.targets = std::move(targets).value();
  } else if (native_targets != nullptr) {
    a.targets = *native_targets;
  } else if (targets_required) {
    return make_error(file, "targets", std::string("required by the ") + backend + " backend");
  }
  if (!cfg.model_path.empty()) {
    auto model = load_model(cfg.model_path, a.targets);
    if (!model) return make_error(file, "model", model.error().message);
    a.model = std::move(model).value();
  } else if (native_model != nullptr && cfg.targets_path.empty()) {
    a.model = *native_model;  // the native model belongs to the native targets
  }
  if (auto r = check_capacities(
          file, a,
          cfg.targets_path.empty() ? std::string("the backend's targets") : cfg.targets_path,
          cfg.model_path.empty() ? std::string("the backend's model") : cfg.model_path);
      !r)
    return r.error();
  // Every camera of the rig takes part (interfaces.md, "Extensions"): one configured
  // camera per rig camera, in rig order.
  if (a.rig.cameras.size() != cfg.cameras.size()) {
    return make_error(file, "cameras",
                      std::to_string(cfg.cameras.size()) + " cameras, the rig has " +
                          std::to_string(a.rig.cameras.size()) +
                          " (list one camera per rig camera, in rig order)");
  }
  for (std::size_t c = 0; c < cfg.cameras.size(); ++c) {
    const CameraSettings& s = cfg.cameras[c];
    const CameraModel& m = a.rig.cameras[c];
    if (s.width != 0 && (s.width != m.width || s.height != m.height)) {
      return make_error(file, "cameras[" + std::to_string(c) + "].width",
                        std::to_string(s.width) + "x" + std::to_string(s.height) +
                            " does not match the rig's camera '" + m.name + "' (" +
                            std::to_string(m.width) + "x" + std::to_string(m.height) + ")");
    }
  }
  return a;
}

Expected<void> check_capacities(const std::string& file, const TrackingAssets& assets,
                                const std::string& targets_file, const std::string& model_file) {
  static_assert(client::kMaxJoints >= kMaxBodies, "every chain joint fits the message");
  const auto n = [](std::size_t v) { return std::to_string(v); };
  const std::vector<MarkerTarget>& bodies = assets.targets.bodies;
  if (bodies.size() > static_cast<std::size_t>(kMaxBodies)) {
    return make_error(file, "targets",
                      targets_file + ": bodies: " + n(bodies.size()) + " bodies, at most " +
                          n(kMaxBodies) + " (the compiled capacity kMaxBodies)");
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].markers_body.size() > static_cast<std::size_t>(kMaxMarkers)) {
      return make_error(file, "targets",
                        targets_file + ": bodies[" + n(b) + "] '" + bodies[b].name +
                            "': " + n(bodies[b].markers_body.size()) + " markers, at most " +
                            n(kMaxMarkers) + " (the compiled capacity kMaxMarkers)");
    }
  }
  if (assets.model && assets.model->joints.size() > static_cast<std::size_t>(kMaxBodies)) {
    return make_error(file, "model",
                      model_file + ": joints: " + n(assets.model->joints.size()) +
                          " joints, at most " + n(kMaxBodies) +
                          " (the compiled capacity kMaxBodies)");
  }
  return {};
}

Expected<void> check_tracking_assets(const RunConfig& cfg, bool targets_required) {
  const std::string file = cfg.path.empty() ? std::string("mocap run") : cfg.path;
  Expected<TrackingAssets> assets = Error{};
  switch (cfg.cameras[0].backend) {
    case CameraBackend::kSim: {
      auto scene = sim::make_scene(sim_options(cfg));
      if (!scene) return scene.error();
      assets = load_tracking_assets(cfg, &scene->rig, &scene->targets, &scene->joints_true);
      break;
    }
    case CameraBackend::kReplay: {
      auto rec = Recording::open(cfg.cameras[0].device);
      if (!rec) return make_error(file, "cameras[0].device", rec.error().message);
      assets = load_tracking_assets(cfg, &rec->rig(), nullptr, nullptr, targets_required);
      break;
    }
    case CameraBackend::kV4l2:
    case CameraBackend::kLibcamera:
    case CameraBackend::kNode:  // the rig file (rig:) is required
      assets = load_tracking_assets(cfg, nullptr, nullptr, nullptr, targets_required);
      break;
  }
  if (!assets) return assets.error();
  const JointModel* model = assets->model ? &*assets->model : nullptr;
  auto proc = FrameProcessor::create(assets->rig, assets->targets, model, cfg.tracker);
  if (!proc) return make_error(file, "", proc.error().message);
  return {};
}

}  // namespace mocap::config
