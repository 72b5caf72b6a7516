// Design: the YAML reader of the run configuration (run_config.h). One function per
// section, each a Section with its accepted keys (unknown keys fail at once) and typed,
// range-checked getters; cross-key rules (same backend on both cameras, device needed
// or forbidden by the backend, ...) follow the per-key checks; finally the referenced
// files are loaded and the whole tracker is built once (tracking_assets.h) so that a
// configuration that passes here cannot fail later for a reason visible in the files.
#include "config/run_config.h"

#include <unistd.h>

#include <filesystem>
#include <numbers>

#include "config/config_reader.h"
#include "config/tracking_assets.h"
#include "formats/rig_yaml.h"
#include "formats/text_io.h"
#include "formats/yaml_read.h"
#include "sim/scene_cameras.h"
#include "sim/scene_humanoid.h"

namespace mocap::config {

using config_detail::Section;
using formats_detail::fail;
using formats_detail::index_path;
using formats_detail::line_suffix;

namespace {

namespace fs = std::filesystem;

std::string resolve(const std::string& base_dir, const std::string& p) {
  fs::path path(p);
  if (path.is_relative()) path = fs::path(base_dir) / path;
  path = path.lexically_normal();
  if (!path.has_filename() && path.has_parent_path()) path = path.parent_path();  // "rec/"
  return path.string();
}

// > 0 and <= hi.
std::optional<double> positive(const Section& s, std::string_view key, double hi) {
  const auto v = s.number(key, 0.0, hi);
  if (v && *v <= 0.0) s.bad(key, "must be > 0");
  return v;
}

template <class T, class U>
void set(T& dst, const std::optional<U>& v) {
  if (v) dst = static_cast<T>(*v);
}

void read_camera(const YAML::Node& node, const std::string& where, const std::string& dir,
                 CameraSettings& cam) {
  const Section s(node, where,
                  {"backend", "device", "format", "width", "height", "exposure_us", "gain",
                   "trigger", "frame_rate_hz", "buffers", "camera"});
  if (!s.has("backend")) fail(s.path("backend"), "missing key" + line_suffix(node));
  cam.backend = *s.choice<CameraBackend>("backend", {{"sim", CameraBackend::kSim},
                                                     {"replay", CameraBackend::kReplay},
                                                     {"v4l2", CameraBackend::kV4l2},
                                                     {"libcamera", CameraBackend::kLibcamera},
                                                     {"node", CameraBackend::kNode}});
  const char* backend = to_string(cam.backend);
  const bool native = cam.backend == CameraBackend::kSim || cam.backend == CameraBackend::kReplay;
  if (const auto d = s.text("device")) {
    if (cam.backend == CameraBackend::kSim) s.bad("device", "not used by the sim backend");
    const bool named =
        cam.backend == CameraBackend::kLibcamera || cam.backend == CameraBackend::kNode;
    cam.device = named ? *d : resolve(dir, *d);
  } else if (cam.backend != CameraBackend::kSim) {
    fail(s.path("device"), std::string("missing key (the ") + backend + " backend needs " +
                               (cam.backend == CameraBackend::kReplay ? "the recording folder"
                                : cam.backend == CameraBackend::kV4l2 ? "the device node"
                                : cam.backend == CameraBackend::kNode ? "NODE/CAMERA"
                                                                      : "a camera id or index") +
                               ")" + line_suffix(node));
  }
  set(cam.format, s.choice<PixelFormat>(
                      "format", {{"GREY", PixelFormat::kMono8}, {"Y16", PixelFormat::kMono16}}));
  for (const char* key : {"width", "height", "exposure_us", "gain", "format"}) {
    if (native && s.has(key))
      s.bad(key, std::string("not used by the ") + backend + " backend (its images set it)");
  }
  set(cam.width, s.integer("width", 1, 32768));
  set(cam.height, s.integer("height", 1, 32768));
  if ((cam.width == 0) != (cam.height == 0)) {
    fail(s.path(cam.width == 0 ? "width" : "height"),
         "width and height must be given together" + line_suffix(node));
  }
  if (const auto v = s.integer("exposure_us", 1, 10'000'000))
    cam.exposure_us = static_cast<int>(*v);
  if (const auto v = s.number("gain", 0.0, 1e6)) cam.gain = *v;
  config_detail::read_node_camera_keys(s, cam);  // trigger (+ central), camera, node device
  cam.frame_rate_hz = positive(s, "frame_rate_hz", 10000.0);
  if (const auto v = s.integer("buffers", 2, 64)) cam.buffers = static_cast<int>(*v);
}

void read_cameras(const YAML::Node& node, const std::string& dir, RunConfig& cfg, ConfigRole role) {
  formats_detail::require_list(node, "cameras");
  const std::size_t n = node.size();
  const std::size_t lo = role == ConfigRole::kNode ? 1 : static_cast<std::size_t>(kMinCameras);
  // A node publishes at most kMaxNodeCameras; the central rig (any backend) up to
  // kMaxCameras (the pipeline is sized from the count: docs/operations.md).
  const auto hi =
      static_cast<std::size_t>(role == ConfigRole::kNode ? kMaxNodeCameras : kMaxCameras);
  if (n < lo || n > hi) {
    fail("cameras", std::to_string(n) + (n == 1 ? " camera, " : " cameras, ") +
                        (n < lo ? "at least " : "at most ") + std::to_string(n < lo ? lo : hi) +
                        line_suffix(node));
  }
  cfg.cameras.assign(n, CameraSettings{});
  for (std::size_t c = 0; c < n; ++c) {
    read_camera(node[c], index_path("cameras", c), dir, cfg.cameras[c]);
    if (cfg.cameras[c].central_trigger && role != ConfigRole::kNode)
      fail(index_path("cameras", c) + ".trigger",
           "'central' is for the cameras of a `mocap node`" + line_suffix(node[c]));
  }
  const CameraSettings& a = cfg.cameras[0];
  for (std::size_t c = 1; c < n; ++c) {
    const CameraSettings& b = cfg.cameras[c];
    const std::string where = index_path("cameras", c);
    if (a.backend != b.backend) {
      fail(where + ".backend", std::string("must match cameras[0].backend (") +
                                   to_string(a.backend) + "), got " + to_string(b.backend) +
                                   line_suffix(node[c]));
    }
    if (a.backend == CameraBackend::kReplay && a.device != b.device) {
      fail(where + ".device", "must name the same recording as cameras[0].device (" + a.device +
                                  ")" + line_suffix(node[c]));
    }
    for (std::size_t o = 0;
         o < c && a.backend != CameraBackend::kReplay && a.backend != CameraBackend::kSim; ++o) {
      if (cfg.cameras[o].device == b.device)
        fail(where + ".device", "the same device as " + index_path("cameras", o) + ": '" +
                                    b.device + "'" + line_suffix(node[c]));
    }
  }
}

void read_pipeline(const YAML::Node& node, PipelineSettings& p) {
  const Section s(node, "pipeline",
                  {"trigger_rate_hz", "pacing", "realtime", "lock_memory", "cpu_latency_us",
                   "dequeue_timeout_ms", "stages", "pair_by", "pair_tolerance_us", "every_frame",
                   "catch_up_ms"});
  config_detail::read_pair_keys(s, p);
  set(p.trigger_rate_hz, s.number("trigger_rate_hz", kMinTriggerRateHz, kMaxTriggerRateHz));
  set(p.pacing, s.choice<TriggerPacing>("pacing", {{"periodic", TriggerPacing::kPeriodic},
                                                   {"lockstep", TriggerPacing::kLockstep}}));
  set(p.realtime, s.flag("realtime"));
  set(p.every_frame, s.flag("every_frame"));
  set(p.catch_up_ms, s.integer("catch_up_ms", 0, kMaxCatchUpMs));
  set(p.lock_memory, s.flag("lock_memory"));
  // rt::kMaxCpuLatencyUs (rt/cpu_latency.h; config does not link the rt layer).
  set(p.cpu_latency_us, s.integer("cpu_latency_us", -1, 1'000'000));
  set(p.dequeue_timeout_ms, s.integer("dequeue_timeout_ms", 1, 1000));
  // Keys: the stage kinds, then detect0..detect<kMaxCameras-1> (one camera's detect stage).
  std::vector<std::string> keys(kStageNames.begin(), kStageNames.end());
  for (int c = 0; c < kMaxCameras; ++c) keys.push_back("detect" + std::to_string(c));
  const std::vector<std::string_view> key_views(keys.begin(), keys.end());
  const Section stages(s.node("stages"), s.path("stages"), key_views);
  const long cpus = sysconf(_SC_NPROCESSORS_CONF);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Section st(stages.node(keys[i]), stages.path(keys[i]), {"cpu", "priority", "ring_depth"});
    StageSettings& out = i < kStageCount ? p.stages[i] : p.detect_camera[i - kStageCount];
    if (const auto v = st.integer("cpu", -1, 1023)) {
      if (cpus > 0 && *v >= cpus)
        st.bad("cpu", "this machine has CPUs 0.." + std::to_string(cpus - 1) + ", got " +
                          std::to_string(*v));
      out.cpu = static_cast<int>(*v);
    }
    if (const auto v = st.integer("priority", 0, 99)) out.priority = static_cast<int>(*v);
    if (i == 0 && st.has("ring_depth")) st.bad("ring_depth", "the capture stage has no input ring");
    if (const auto v = st.integer("ring_depth", 2, 1024))
      out.ring_depth = static_cast<std::uint32_t>(*v);
  }
}

void read_detection(const YAML::Node& node, detect::DetectorConfig& d) {
  const Section s(
      node, "detection",
      {"threshold_mode", "threshold_dn", "background_dn", "threshold_sigma", "min_contrast_dn",
       "min_area_px", "max_area_px", "max_elongation", "border", "max_blobs", "roi"});
  set(d.threshold_mode, s.choice<detect::ThresholdMode>(
                            "threshold_mode", {{"adaptive", detect::ThresholdMode::kAdaptive},
                                               {"fixed", detect::ThresholdMode::kFixed}}));
  set(d.threshold_dn, s.integer("threshold_dn", 1, 65535));
  set(d.background_dn, s.integer("background_dn", 0, 65534));
  if (d.background_dn >= d.threshold_dn && (s.has("background_dn") || s.has("threshold_dn")))
    s.bad(s.has("background_dn") ? "background_dn" : "threshold_dn",
          "background_dn must be below threshold_dn");
  set(d.threshold_sigma, s.number("threshold_sigma", 0.0, 1000.0));
  set(d.min_contrast_dn, s.integer("min_contrast_dn", 1, 65535));
  set(d.min_area_px, s.integer("min_area_px", 1, 1'000'000));
  set(d.max_area_px, s.integer("max_area_px", 1, 100'000'000));
  if (d.max_area_px < d.min_area_px)
    s.bad(s.has("max_area_px") ? "max_area_px" : "min_area_px",
          "max_area_px must be >= min_area_px");
  set(d.max_elongation, s.number("max_elongation", 1.0, 100.0));
  set(d.border,
      s.choice<detect::BorderPolicy>("border", {{"flag", detect::BorderPolicy::kFlag},
                                                {"reject", detect::BorderPolicy::kReject}}));
  set(d.max_blobs, s.integer("max_blobs", 1, 1 << 20));
  if (s.has("roi")) {
    const Section r(s.node("roi"), s.path("roi"), {"x", "y", "width", "height"});
    set(d.roi.x, r.integer("x", 0, 32767));
    set(d.roi.y, r.integer("y", 0, 32767));
    set(d.roi.width, r.integer("width", 1, 32768));
    set(d.roi.height, r.integer("height", 1, 32768));
    if (!r.has("width") || !r.has("height"))
      fail(s.path("roi"), "width and height are required" + line_suffix(s.node("roi")));
  }
}

void read_stereo(const YAML::Node& node, StereoConfig& c) {
  const Section s(node, "stereo",
                  {"epipolar_tolerance_px", "max_reproj_px", "min_depth_mm", "max_depth_mm",
                   "max_points_per_camera"});
  set(c.epipolar_tolerance_px, positive(s, "epipolar_tolerance_px", 100.0));
  set(c.max_reproj_px, positive(s, "max_reproj_px", 100.0));
  set(c.min_depth_mm, s.number("min_depth_mm", 0.0, 1e6));
  set(c.max_depth_mm, positive(s, "max_depth_mm", 1e7));
  if (c.max_depth_mm <= c.min_depth_mm)
    s.bad(s.has("max_depth_mm") ? "max_depth_mm" : "min_depth_mm",
          "max_depth_mm must be above min_depth_mm");
  set(c.max_points_per_camera, s.integer("max_points_per_camera", 1, 32767));
}

void read_identification(const YAML::Node& node, IdentifyConfig& c) {
  const Section s(
      node, "identification",
      {"t_mm", "min_markers", "best_pairs", "ambiguity_ratio", "residual_floor_mm",
       "max_search_nodes", "temporal", "warm_gate_mm", "warm_min_markers", "max_prior_age_s",
       "max_speed_mm_per_s", "max_angular_speed_deg_per_s", "max_acceleration_mm_per_s2",
       "point_sigma_mm", "partial_sigma_mm", "consistency_confidence", "exclude_partial_markers",
       "min_whole_markers", "max_points"});
  set(c.t_mm, positive(s, "t_mm", 1000.0));
  set(c.min_markers, s.integer("min_markers", 3, 64));
  set(c.best_pairs, s.integer("best_pairs", 1, 100000));
  set(c.ambiguity_ratio, s.number("ambiguity_ratio", 0.0, 100.0));
  set(c.residual_floor_mm, s.number("residual_floor_mm", 0.0, 100.0));
  set(c.max_search_nodes, s.integer("max_search_nodes", 1, 1'000'000'000));
  set(c.temporal, s.flag("temporal"));
  set(c.warm_gate_mm, positive(s, "warm_gate_mm", 1000.0));
  set(c.warm_min_markers, s.integer("warm_min_markers", 3, 64));
  set(c.max_prior_age_s, s.number("max_prior_age_s", 0.0, 60.0));
  set(c.max_speed_mm_per_s, s.number("max_speed_mm_per_s", 0.0, 1e6));
  set(c.max_angular_speed_deg_per_s, s.number("max_angular_speed_deg_per_s", 0.0, 1e6));
  // 0: max_speed x max_angular_speed (identify/motion.h derives the gates from it).
  set(c.max_acceleration_mm_per_s2, s.number("max_acceleration_mm_per_s2", 0.0, 1e9));
  set(c.point_sigma_mm, s.number("point_sigma_mm", 0.0, 100.0));
  set(c.partial_sigma_mm, s.number("partial_sigma_mm", 0.0, 100.0));
  set(c.consistency_confidence, s.number("consistency_confidence", 0.99, 0.999999));
  set(c.exclude_partial_markers, s.flag("exclude_partial_markers"));
  set(c.min_whole_markers, s.integer("min_whole_markers", 0, 16));
  // 3D points per frame identification takes (its pair table costs 24 bytes x n^2/2 at
  // setup: docs/formats.md, "Capacities"); bounded by the compiled kMaxPoints.
  set(c.max_points, s.integer("max_points", 3, kMaxPoints));
}

// The joint- and body-rate filters (kinematics/joint_rates.h, body_rates.h), in the units
// of their keys.
void read_velocity(const YAML::Node& node, kinematics::RateFilterConfig& c) {
  const Section s(node, "velocity",
                  {"max_gap_ms", "warmup_frames", "jerk_psd_deg2_per_s5", "min_angle_sd_deg",
                   "body_jerk_psd_mm2_per_s5", "min_position_sd_mm"});
  constexpr double kRad = std::numbers::pi / 180.0;
  if (const auto v = positive(s, "max_gap_ms", 60'000.0)) c.max_gap_s = *v * 1e-3;
  set(c.warmup_observations, s.integer("warmup_frames", 1, 100));
  if (const auto v = positive(s, "jerk_psd_deg2_per_s5", 1e12))
    c.jerk_psd_rad2_s5 = *v * kRad * kRad;
  if (const auto v = positive(s, "min_angle_sd_deg", 10.0)) c.min_angle_sd_rad = *v * kRad;
  if (const auto v = positive(s, "body_jerk_psd_mm2_per_s5", 1e15)) c.body_jerk_psd_mm2_s5 = *v;
  if (const auto v = positive(s, "min_position_sd_mm", 10.0)) c.min_position_sd_mm = *v;
}

Expected<RunConfig> parse(const std::string& path, const YAML::Node& root, ConfigRole role) {
  RunConfig cfg;
  cfg.path = path;
  const std::string dir = fs::path(path).parent_path().string();
  const std::string base = dir.empty() ? std::string(".") : dir;
  const Section top(
      root, "",
      {"version", "cameras", "rig", "targets", "model", "pipeline", "outputs", "detection",
       "stereo", "identification", "velocity", "sim", "service", "fault_injection", "node"});
  (void)top.integer("version", 1, 1);  // the only version so far; checked for the future
  if (top.has("cameras")) read_cameras(top.node("cameras"), base, cfg, role);
  config_detail::read_node_section(top.node("node"), cfg.cameras, cfg.node);
  if (const auto v = top.text("rig")) cfg.rig_path = resolve(base, *v);
  if (const auto v = top.text("targets")) cfg.targets_path = resolve(base, *v);
  if (const auto v = top.text("model")) cfg.model_path = resolve(base, *v);
  read_pipeline(top.node("pipeline"), cfg.pipeline);
  config_detail::read_outputs(path, top.node("outputs"), cfg.outputs);
  read_detection(top.node("detection"), cfg.tracker.detect);
  read_stereo(top.node("stereo"), cfg.tracker.stereo);
  read_identification(top.node("identification"), cfg.tracker.identify);
  read_velocity(top.node("velocity"), cfg.tracker.velocity);
  const Section sim(top.node("sim"), "sim", {"loop_frames", "scene", "cameras", "rig"});
  set(cfg.sim.loop_frames, sim.integer("loop_frames", kMinLoopFrames, kMaxLoopFrames));
  set(cfg.sim.scene,
      sim.choice<mocap::sim::SceneKind>("scene", {{"limbs", mocap::sim::SceneKind::kLimbs},
                                                  {"stalks", mocap::sim::SceneKind::kStalks},
                                                  {"humanoid", mocap::sim::SceneKind::kHumanoid}}));
  const bool humanoid = cfg.sim.scene == mocap::sim::SceneKind::kHumanoid;
  // The humanoid's loop: 8 x 1280x1024 images per frame (10.5 MB), so 100 frames by
  // default (1 GB, pre-rendered at start).
  if (humanoid && !sim.has("loop_frames")) cfg.sim.loop_frames = kHumanoidLoopFrames;
  for (const char* key : {"loop_frames", "scene", "cameras", "rig"}) {
    if (sim.has(key) && cfg.cameras[0].backend != CameraBackend::kSim)
      sim.bad(key, std::string("only used by the sim backend (cameras use ") +
                       to_string(cfg.cameras[0].backend) + ")");
  }
  // The simulated camera count: sim.cameras, sim.rig's cameras or the length of the
  // cameras list (any of them, agreeing); kept as cfg.cameras.size() (its one home).
  // The built-in cameras: the humanoid's ring up to kMaxSimCameras, the arc up to 8.
  std::optional<std::int64_t> sim_cameras = sim.integer(
      "cameras", kMinCameras, humanoid ? mocap::sim::kMaxSimCameras : mocap::sim::kMaxArcCameras);
  if (humanoid && !sim_cameras && !sim.has("rig") && !top.has("cameras"))
    sim_cameras = mocap::sim::kHumanoidDefaultCameras;  // the humanoid's ring
  if (const auto v = sim.text("rig")) {
    cfg.sim.rig_path = resolve(base, *v);
    const auto rig = load_rig(cfg.sim.rig_path);
    if (!rig) sim.bad("rig", rig.error().message);
    const auto n = static_cast<std::int64_t>(rig->cameras.size());
    if (sim_cameras && *sim_cameras != n)
      sim.bad("cameras",
              std::to_string(*sim_cameras) + " cameras, but sim.rig has " + std::to_string(n));
    sim_cameras = n;
  }
  if (sim_cameras) {
    if (top.has("cameras") && static_cast<std::size_t>(*sim_cameras) != cfg.cameras.size())
      sim.bad(sim.has("cameras") ? "cameras" : "rig", std::to_string(*sim_cameras) +
                                                          " cameras, but the cameras list has " +
                                                          std::to_string(cfg.cameras.size()));
    if (!top.has("cameras"))
      cfg.cameras.assign(static_cast<std::size_t>(*sim_cameras), CameraSettings{});
  }
  for (std::size_t k = cfg.cameras.size(); k < cfg.pipeline.detect_camera.size(); ++k) {
    const StageSettings& d = cfg.pipeline.detect_camera[k];
    if (d.cpu || d.priority || d.ring_depth)
      fail("pipeline.stages.detect" + std::to_string(k), "no camera " + std::to_string(k) + " (" +
                                                             std::to_string(cfg.cameras.size()) +
                                                             " cameras)");
  }
  const Section svc(top.node("service"), "service", {"status_interval_s", "log_interval_s"});
  set(cfg.service.status_interval_s, svc.number("status_interval_s", 0.1, 3600.0));
  set(cfg.service.log_interval_s, svc.number("log_interval_s", 0.0, 86400.0));
  const Section faults(top.node("fault_injection"), "fault_injection", {"stall_after_frames"});
  set(cfg.faults.stall_after_frames, faults.integer("stall_after_frames", 1, 1'000'000'000'000));
  return cfg;
}

}  // namespace

Expected<RunConfig> load_run_config(const std::string& path, bool targets_required,
                                    ConfigRole role) {
  std::string text;
  if (auto r = formats_detail::read_text_file(path, text, formats_detail::kMaxYamlFileBytes); !r)
    return r.error();
  auto cfg = formats_detail::guard<RunConfig>(path, [&]() -> Expected<RunConfig> {
    const YAML::Node root = YAML::Load(text);
    if (!root.IsDefined() || root.IsNull()) return make_error(path, "", "empty file");
    if (!root.IsMap())
      fail("top level",
           "expected a map, got " + formats_detail::describe(root) + line_suffix(root));
    return parse(path, root, role);
  });
  if (!cfg) return cfg;
  if (role == ConfigRole::kNode)
    return cfg;  // no tracker on a node: `mocap node` opens the cameras
  if (auto r = check_tracking_assets(*cfg, targets_required); !r) return r.error();
  return cfg;
}

}  // namespace mocap::config
