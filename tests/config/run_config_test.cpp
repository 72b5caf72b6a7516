// Design: the run configuration's happy paths: the shipped example (deploy/mocap.yaml),
// defaults, relative path resolution, the replay and v4l2 backends with real rig and
// targets files written from the simulator's scene, and the asset resolution rules.
#include "config/run_config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "config/tracking_assets.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::config {
namespace {

using test::TempDir;
using test::write_file;

// rig.yaml, targets.yaml and a 2-frame recording (frames.csv only) of the sim scene.
void write_scene_files(const std::string& dir) {
  std::filesystem::create_directories(dir + "/rec/cam0");
  std::filesystem::create_directories(dir + "/rec/cam1");
  auto scene = sim::make_scene(sim::SimOptions{});
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", scene->rig));
  ASSERT_TRUE(save_targets(dir + "/targets.yaml", scene->targets));
  ASSERT_TRUE(save_rig(dir + "/rec/rig.yaml", scene->rig)) << "rec/";
  ASSERT_TRUE(save_frames_csv(dir + "/rec/frames.csv", {{0, 0}, {1, 10'000'000}}));
}

TEST(RunConfig, ShippedExampleLoads) {
  auto cfg = load_run_config(test::source_dir() + "/deploy/mocap.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->cameras[0].backend, CameraBackend::kSim);
  EXPECT_EQ(cfg->cameras[0].trigger, TriggerMode::kSoftware);
  EXPECT_EQ(cfg->cameras[1].trigger, TriggerMode::kExternal);
  EXPECT_DOUBLE_EQ(cfg->pipeline.trigger_rate_hz, 100.0);
  ASSERT_TRUE(cfg->pipeline.stages[2].cpu.has_value());  // identify
  EXPECT_EQ(*cfg->pipeline.stages[2].cpu, 1);
  EXPECT_EQ(*cfg->pipeline.stages[1].ring_depth, 3u);  // the detect rule
  EXPECT_FALSE(cfg->pipeline.stages[0].ring_depth.has_value());
  EXPECT_FALSE(cfg->pipeline.detect_camera[1].cpu.has_value());
  ASSERT_EQ(cfg->outputs.udp.size(), 1u);
  EXPECT_EQ(cfg->outputs.udp[0], "127.0.0.1:7755");
  EXPECT_DOUBLE_EQ(cfg->tracker.detect.max_elongation, 1.3);
  EXPECT_DOUBLE_EQ(cfg->service.status_interval_s, 1.0);
}

TEST(RunConfig, MinimalFileKeepsTheDefaults) {
  TempDir dir("cfg_min");
  write_file(dir.file("m.yaml"), "version: 1\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  const RunConfig def = default_run_config();
  EXPECT_EQ(cfg->cameras[0].backend, def.cameras[0].backend);
  EXPECT_EQ(cfg->outputs.udp, def.outputs.udp);
  EXPECT_TRUE(cfg->outputs.iceoryx);
  EXPECT_EQ(cfg->sim.loop_frames, def.sim.loop_frames);
  EXPECT_DOUBLE_EQ(cfg->tracker.identify.t_mm, TrackerConfig{}.identify.t_mm);
  EXPECT_EQ(cfg->faults.stall_after_frames, 0u);
  EXPECT_FALSE(cfg->pipeline.stages[3].priority.has_value());
  EXPECT_EQ(cfg->cameras.size(), 2u);
}

TEST(RunConfig, NodeKeysAreRead) {
  TempDir dir("cfg_node");
  // A node: one camera, trigger: central, a named camera of the recording; no tracker.
  write_file(dir.file("node.yaml"),
             "node: {name: node-a, domain_id: 7}\n"
             "cameras: [{backend: replay, device: rec, camera: cam3, trigger: central}]\n");
  auto node = load_run_config(dir.file("node.yaml"), false, ConfigRole::kNode);
  ASSERT_TRUE(node) << node.error().message;
  ASSERT_EQ(node->cameras.size(), 1u);
  EXPECT_TRUE(node->cameras[0].central_trigger);
  EXPECT_EQ(node->cameras[0].trigger, TriggerMode::kSoftware);
  EXPECT_EQ(node->cameras[0].recording_camera, "cam3");
  EXPECT_EQ(node->node.name, "node-a");
  EXPECT_EQ(node->node.domain_id, 7u);
  // The same file is not a central configuration (one camera, trigger: central).
  EXPECT_FALSE(load_run_config(dir.file("node.yaml")));
  // The central: node cameras, pairing by timestamp, the fault timing.
  auto scene = sim::make_scene(sim::SimOptions{});
  ASSERT_TRUE(scene);
  ASSERT_TRUE(save_rig(dir.file("rig.yaml"), scene->rig));
  ASSERT_TRUE(save_targets(dir.file("targets.yaml"), scene->targets));
  write_file(dir.file("central.yaml"),
             "node: {domain_id: 7, timeout_ms: 40, wait_s: 2.5}\nrig: rig.yaml\n"
             "targets: targets.yaml\n"
             "cameras: [{backend: node, device: node-a/cam0}, {backend: node, device: b/c}]\n"
             "pipeline: {pair_by: timestamp, pair_tolerance_us: 500}\n");
  auto central = load_run_config(dir.file("central.yaml"));
  ASSERT_TRUE(central) << central.error().message;
  EXPECT_EQ(central->cameras[0].backend, CameraBackend::kNode);
  EXPECT_EQ(central->cameras[1].device, "b/c");
  EXPECT_EQ(central->node.timeout_ms, 40);
  EXPECT_DOUBLE_EQ(central->node.wait_s, 2.5);
  EXPECT_EQ(central->pipeline.pair_by, PairBy::kTimestamp);
  EXPECT_EQ(central->pipeline.pair_tolerance_us, 500);
}

// A rig of more than 8 cameras over nodes (kMaxCameras is 32): 12 node cameras, two
// nodes of 6, load against the humanoid's 12-camera ring; a node itself takes at most 8.
TEST(RunConfig, TwelveNodeCamerasLoadAndANodeTakesAtMostEight) {
  TempDir dir("cfg_node12");
  sim::SimOptions so;
  so.scene = sim::SceneKind::kHumanoid;
  so.cameras = 12;
  auto scene = sim::make_scene(so);
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_TRUE(save_rig(dir.file("rig.yaml"), scene->rig));
  ASSERT_TRUE(save_targets(dir.file("targets.yaml"), scene->targets));
  std::string yaml = "rig: rig.yaml\ntargets: targets.yaml\ncameras:\n";
  for (int c = 0; c < 12; ++c)
    yaml += "  - {backend: node, device: n" + std::to_string(c / 6) + "/cam" + std::to_string(c) +
            "}\n";
  write_file(dir.file("central.yaml"), yaml);
  auto central = load_run_config(dir.file("central.yaml"));
  ASSERT_TRUE(central) << central.error().message;
  ASSERT_EQ(central->cameras.size(), 12u);
  EXPECT_EQ(central->cameras[11].device, "n1/cam11");
  std::string node = "cameras:\n";
  for (int c = 0; c < 9; ++c)
    node += "  - {backend: v4l2, device: /dev/video" + std::to_string(c) +
            ", width: 640, height: 480}\n";
  write_file(dir.file("node.yaml"), node);
  auto nine = load_run_config(dir.file("node.yaml"), false, ConfigRole::kNode);
  ASSERT_FALSE(nine);
  EXPECT_EQ(nine.error().message,
            dir.file("node.yaml") + ": cameras: 9 cameras, at most 8 (line 2)");
}

TEST(RunConfig, ThresholdsAndOutputsAreRead) {
  TempDir dir("cfg_thr");
  write_file(
      dir.file("m.yaml"),
      "outputs: {udp: ['10.0.0.2:9000', 'robot.local:7755'], iceoryx: false}\n"
      "detection: {threshold_mode: fixed, threshold_dn: 60, background_dn: 10,\n"
      "            roi: {x: 10, y: 20, width: 100, height: 50}, border: reject}\n"
      "stereo: {epipolar_tolerance_px: 1.5, min_depth_mm: 200, max_depth_mm: 5000}\n"
      "identification: {t_mm: 4, min_markers: 4, temporal: false}\n"
      "pipeline: {pacing: lockstep, realtime: false, cpu_latency_us: 50, every_frame: true,\n"
      "           catch_up_ms: 40,\n"
      "           stages: {publish: {cpu: -1}}}\n"
      "fault_injection: {stall_after_frames: 50}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->outputs.udp.size(), 2u);
  EXPECT_FALSE(cfg->outputs.iceoryx);
  EXPECT_EQ(cfg->tracker.detect.threshold_mode, detect::ThresholdMode::kFixed);
  EXPECT_EQ(cfg->tracker.detect.threshold_dn, 60);
  EXPECT_EQ(cfg->tracker.detect.roi.height, 50);
  EXPECT_EQ(cfg->tracker.detect.border, detect::BorderPolicy::kReject);
  EXPECT_DOUBLE_EQ(cfg->tracker.stereo.max_depth_mm, 5000.0);
  EXPECT_EQ(cfg->tracker.identify.min_markers, 4);
  EXPECT_FALSE(cfg->tracker.identify.temporal);
  EXPECT_EQ(cfg->pipeline.pacing, TriggerPacing::kLockstep);
  EXPECT_FALSE(cfg->pipeline.realtime);
  EXPECT_TRUE(cfg->pipeline.every_frame);
  EXPECT_EQ(cfg->pipeline.catch_up_ms, 40);
  EXPECT_EQ(cfg->pipeline.cpu_latency_us, 50);
  EXPECT_EQ(*cfg->pipeline.stages[3].cpu, -1);
  EXPECT_EQ(cfg->faults.stall_after_frames, 50u);
}

TEST(RunConfig, SimCameraCountAndDetectStages) {
  TempDir dir("cfg_ncam");
  write_file(dir.file("m.yaml"),
             "sim: {cameras: 4, loop_frames: 2}\n"
             "pipeline: {stages: {detect: {priority: 65}, detect3: {cpu: -1, ring_depth: 5}}}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  ASSERT_EQ(cfg->cameras.size(), 4u);
  EXPECT_EQ(cfg->cameras[3].backend, CameraBackend::kSim);
  EXPECT_EQ(*cfg->pipeline.stages[1].priority, 65);
  EXPECT_EQ(*cfg->pipeline.detect_camera[3].cpu, -1);
  EXPECT_EQ(*cfg->pipeline.detect_camera[3].ring_depth, 5u);
  EXPECT_FALSE(cfg->pipeline.detect_camera[2].cpu.has_value());
}

TEST(RunConfig, UdpMapFormChoosesTheDatagramVersionAndVelocityIsRead) {
  TempDir dir("cfg_udpv2");
  write_file(dir.file("m.yaml"),
             "outputs: {udp: ['10.0.0.2:9000', {value: '127.0.0.1:7756', version: 2},\n"
             "                {value: '127.0.0.1:7757', version: 1}]}\n"
             "velocity: {max_gap_ms: 50, warmup_frames: 5, jerk_psd_deg2_per_s5: 2e5,\n"
             "           min_angle_sd_deg: 0.05}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  ASSERT_EQ(cfg->outputs.udp.size(), 3u);
  EXPECT_EQ(cfg->outputs.udp[1], "127.0.0.1:7756");
  EXPECT_EQ(cfg->outputs.udp_versions, (std::vector<std::uint16_t>{1, 2, 1}));
  EXPECT_DOUBLE_EQ(cfg->tracker.velocity.max_gap_s, 0.05);
  EXPECT_EQ(cfg->tracker.velocity.warmup_observations, 5);
  EXPECT_NEAR(cfg->tracker.velocity.jerk_psd_rad2_s5, 2e5 * std::pow(M_PI / 180.0, 2), 1e-9);
  EXPECT_NEAR(cfg->tracker.velocity.min_angle_sd_rad, 0.05 * M_PI / 180.0, 1e-12);
  // The defaults: one v1 destination.
  write_file(dir.file("d.yaml"), "sim: {loop_frames: 10}\n");
  auto d = load_run_config(dir.file("d.yaml"));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->outputs.udp_versions, (std::vector<std::uint16_t>{1}));
}

TEST(RunConfig, LeadsOfUdpDestinationsAndIceoryxAndBodyVelocityKeys) {
  TempDir dir("cfg_lead");
  write_file(dir.file("m.yaml"),
             "outputs: {udp: ['10.0.0.2:9000', {value: '127.0.0.1:7756', version: 2, "
             "lead_ms: 5}],\n"
             "          iceoryx: {value: true, lead_ms: 2.5}}\n"
             "velocity: {body_jerk_psd_mm2_per_s5: 1e7, min_position_sd_mm: 0.02}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->outputs.udp_leads_ms, (std::vector<double>{0.0, 5.0}));
  EXPECT_EQ(cfg->outputs.udp_versions, (std::vector<std::uint16_t>{1, 2}));
  EXPECT_TRUE(cfg->outputs.iceoryx);
  EXPECT_DOUBLE_EQ(cfg->outputs.iceoryx_lead_ms, 2.5);
  EXPECT_DOUBLE_EQ(cfg->tracker.velocity.body_jerk_psd_mm2_s5, 1e7);
  EXPECT_DOUBLE_EQ(cfg->tracker.velocity.min_position_sd_mm, 0.02);
  // The plain forms: no lead.
  write_file(dir.file("d.yaml"), "outputs: {udp: ['127.0.0.1:1'], iceoryx: false}\n");
  auto d = load_run_config(dir.file("d.yaml"));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->outputs.udp_leads_ms, (std::vector<double>{0.0}));
  EXPECT_FALSE(d->outputs.iceoryx);
  EXPECT_EQ(d->outputs.iceoryx_lead_ms, 0.0);
}

TEST(RunConfig, EmptyUdpListDisablesUdp) {
  TempDir dir("cfg_noudp");
  write_file(dir.file("m.yaml"), "outputs: {udp: []}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->outputs.udp.empty());
}

TEST(RunConfig, HardwareBackendWithRelativeRigAndTargets) {
  TempDir dir("cfg_v4l2");
  write_scene_files(dir.path() + "/calib");
  write_file(dir.file("m.yaml"),
             "cameras:\n"
             "  - {backend: v4l2, device: /dev/video0, format: Y16, width: 1032, height: 776,\n"
             "     exposure_us: 500, gain: 2.5, trigger: external, buffers: 8}\n"
             "  - {backend: v4l2, device: /dev/video1, trigger: external}\n"
             "rig: calib/rig.yaml\n"
             "targets: ./calib/../calib/targets.yaml\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->rig_path, dir.path() + "/calib/rig.yaml");
  EXPECT_EQ(cfg->targets_path, dir.path() + "/calib/targets.yaml");
  EXPECT_TRUE(cfg->model_path.empty());
  const CameraSettings& c0 = cfg->cameras[0];
  EXPECT_EQ(c0.device, "/dev/video0");
  EXPECT_EQ(c0.format, PixelFormat::kMono16);
  EXPECT_EQ(*c0.exposure_us, 500);
  EXPECT_DOUBLE_EQ(*c0.gain, 2.5);
  EXPECT_EQ(*c0.buffers, 8);
  EXPECT_FALSE(cfg->cameras[1].exposure_us.has_value());
  auto assets = load_tracking_assets(*cfg, nullptr, nullptr, nullptr);
  ASSERT_TRUE(assets) << assets.error().message;
  EXPECT_EQ(assets->rig.cameras.size(), 2u);
  EXPECT_FALSE(assets->model.has_value());
}

TEST(RunConfig, ReplayBackendUsesTheRecordingsRig) {
  TempDir dir("cfg_replay");
  write_scene_files(dir.path());
  write_file(dir.file("m.yaml"),
             "cameras: [{backend: replay, device: rec}, {backend: replay, device: rec/}]\n"
             "targets: targets.yaml\n"
             "pipeline: {pacing: lockstep}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->cameras[0].device, dir.path() + "/rec");
}

TEST(RunConfig, SimAssetsDefaultToTheScene) {
  const RunConfig cfg = default_run_config();
  auto scene = sim::make_scene(sim_options(cfg));
  ASSERT_TRUE(scene);
  auto a = load_tracking_assets(cfg, &scene->rig, &scene->targets, &scene->joints_true);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(a->model.has_value());
  EXPECT_EQ(a->model->joints.size(), scene->joints_true.joints.size());
  EXPECT_TRUE(check_tracking_assets(cfg));
}

TEST(RunConfig, SimSceneSelectsTheMarkerLayout) {
  EXPECT_EQ(default_run_config().sim.scene, sim::SceneKind::kLimbs);
  EXPECT_EQ(sim_options(default_run_config()).scene, sim::SceneKind::kLimbs);
  TempDir dir("cfg_scene");
  write_file(dir.file("m.yaml"), "sim: {scene: stalks, loop_frames: 20}\n");
  auto cfg = load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->sim.scene, sim::SceneKind::kStalks);
  const sim::SimOptions so = sim_options(*cfg);
  EXPECT_EQ(so.scene, sim::SceneKind::kStalks);
  auto scene = sim::make_scene(so);
  ASSERT_TRUE(scene);
  EXPECT_EQ(scene->marker_count(), 14);  // the stalk layout's 5 + 5 + 4 balls
  EXPECT_TRUE(check_tracking_assets(*cfg));
}

// sim: {scene: humanoid}: the whole robot on its ring of 8 cameras and a 100-frame loop
// by default (each frame is 8 x 1280x1024 images); sim.cameras and loop_frames still rule.
TEST(RunConfig, SimHumanoidDefaultsToItsRing) {
  TempDir dir("cfg_humanoid");
  write_file(dir.file("h.yaml"), "sim: {scene: humanoid}\n");
  auto cfg = load_run_config(dir.file("h.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->sim.scene, sim::SceneKind::kHumanoid);
  EXPECT_EQ(cfg->cameras.size(), 8u);
  EXPECT_EQ(cfg->sim.loop_frames, kHumanoidLoopFrames);
  write_file(dir.file("h4.yaml"), "sim: {scene: humanoid, cameras: 4, loop_frames: 10}\n");
  auto four = load_run_config(dir.file("h4.yaml"));
  ASSERT_TRUE(four) << four.error().message;
  EXPECT_EQ(four->cameras.size(), 4u);
  EXPECT_EQ(four->sim.loop_frames, 10);
  const sim::SimOptions so = sim_options(*four);
  auto scene = sim::make_scene(so);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->body_count(), 15);
  EXPECT_EQ(scene->rig.cameras.size(), 4u);
  EXPECT_TRUE(check_tracking_assets(*four));
}

TEST(RunConfig, HostPortCheck) {
  EXPECT_TRUE(check_host_port("f", "k", "127.0.0.1:7755"));
  EXPECT_TRUE(check_host_port("f", "k", "[::1]:1"));
  EXPECT_FALSE(check_host_port("f", "k", "host"));
  EXPECT_FALSE(check_host_port("f", "k", ":7755"));
  EXPECT_FALSE(check_host_port("f", "k", "h:0"));
  EXPECT_FALSE(check_host_port("f", "k", "h:65536"));
  EXPECT_FALSE(check_host_port("f", "k", "h:12a"));
  EXPECT_EQ(check_host_port("f", "k", "h:").error().message, "f: k: expected HOST:PORT, got 'h:'");
}

}  // namespace
}  // namespace mocap::config
