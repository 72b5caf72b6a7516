// Design: one test per configuration error. Every case writes a small configuration
// next to a rig, targets file and recording of the simulator's scene, loads it and
// checks the exact one-line error: it starts with the file's path, names the key and
// states the problem.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>

#include "config/run_config.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::config {
namespace {

struct ErrorCase {
  const char* name;
  const char* yaml;
  const char* expected;  // the error after "<file>: "
};

// A v4l2 pair that loads (rig and targets next to the file).
#define V4L2_PAIR                                                                    \
  "cameras:\n  - {backend: v4l2, device: /dev/video0}\n  - {backend: v4l2, device: " \
  "/dev/video1}\n"
#define ASSETS "rig: rig.yaml\ntargets: targets.yaml\n"

const ErrorCase kCases[] = {
    // Camera nodes (issue 29).
    {"CentralTriggerOnTheCentral",
     "cameras: [{backend: replay, device: r, trigger: central}, {backend: replay, device: r}]\n",
     "cameras[0].trigger: 'central' is for the cameras of a `mocap node` (line 1)"},
    {"NodeDeviceWithoutSlash",
     "cameras: [{backend: node, device: a}, {backend: node, device: b/c}]\n",
     "cameras[0].device: expected NODE/CAMERA (the node's name, its camera's name), got 'a' "
     "(line 1)"},
    {"RecordingCameraNotReplay", "cameras: [{backend: sim, camera: x}, {backend: sim}]\n",
     "cameras[0].camera: only replay cameras play a named camera of a recording (line 1)"},
    {"NodeNameWithSpace", "node: {name: 'a b'}\n",
     "node.name: printable characters without spaces or '/', got 'a b' (line 1)"},
    {"NodeDomainOutOfRange", "node: {domain_id: 300}\n",
     "node.domain_id: must be in [0, 232], got 300 (line 1)"},
    {"BadPairBy", "pipeline: {pair_by: time}\n",
     "pipeline.pair_by: expected sequence|timestamp, got 'time' (line 1)"},
    {"UnknownTopLevelKey", "detetcion: {}\n",
     "detetcion: unknown key (line 1); expected one of: version, cameras, rig, targets, model, "
     "pipeline, outputs, detection, stereo, identification, velocity, sim, service, "
     "fault_injection, node"},
    {"UnknownCameraKey", "cameras: [{backend: sim, exposure: 3}, {backend: sim}]\n",
     "cameras[0].exposure: unknown key (line 1); expected one of: backend, device, format, width, "
     "height, exposure_us, gain, trigger, frame_rate_hz, buffers, camera"},
    {"DuplicateKey", "sim: {loop_frames: 10}\nsim: {loop_frames: 20}\n",
     "sim: duplicate key (line 2)"},
    {"TopLevelNotAMap", "- 1\n", "top level: expected a map, got a list (line 1)"},
    {"BadVersion", "version: 2\n", "version: must be in [1, 1], got 2 (line 1)"},
    {"CamerasNotAList", "cameras: {backend: sim}\n",
     "cameras: expected a list, got a map (line 1)"},
    {"OneCamera", "cameras: [{backend: sim}]\n", "cameras: 1 camera, at least 2 (line 1)"},
    {"ThirtyThreeCameras",
     "cameras: [{backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim}, {backend: sim},\n"
     "  {backend: sim}, {backend: sim}, {backend: sim}]\n",
     "cameras: 33 cameras, at most 32 (line 1)"},
    {"SimCamerasDisagree", "cameras: [{backend: sim}, {backend: sim}]\nsim: {cameras: 3}\n",
     "sim.cameras: 3 cameras, but the cameras list has 2 (line 2)"},
    {"SimCamerasRange", "sim: {cameras: 9}\n", "sim.cameras: must be in [2, 8], got 9 (line 1)"},
    {"SimHumanoidCamerasRange", "sim: {scene: humanoid, cameras: 33}\n",
     "sim.cameras: must be in [2, 32], got 33 (line 1)"},
    {"DetectStageWithoutCamera", "pipeline: {stages: {detect2: {cpu: 0}}}\n",
     "pipeline.stages.detect2: no camera 2 (2 cameras)"},
    {"RigHasOtherCameraCount",
     "cameras:\n  - {backend: v4l2, device: /dev/video0}\n  - {backend: v4l2, device: "
     "/dev/video1}\n"
     "  - {backend: v4l2, device: /dev/video2}\n" ASSETS,
     "cameras: 3 cameras, the rig has 2 (list one camera per rig camera, in rig order)"},
    {"MissingBackend", "cameras: [{trigger: software}, {backend: sim}]\n",
     "cameras[0].backend: missing key (line 1)"},
    {"UnknownBackend", "cameras: [{backend: usb}, {backend: sim}]\n",
     "cameras[0].backend: expected sim|replay|v4l2|libcamera|node, got 'usb' (line 1)"},
    {"MixedBackends", "cameras: [{backend: sim}, {backend: v4l2, device: /dev/video0}]\n",
     "cameras[1].backend: must match cameras[0].backend (sim), got v4l2 (line 1)"},
    {"V4l2WithoutDevice", "cameras: [{backend: v4l2}, {backend: v4l2, device: /dev/video1}]\n",
     "cameras[0].device: missing key (the v4l2 backend needs the device node) (line 1)"},
    {"LibcameraWithoutDevice",
     "cameras: [{backend: libcamera}, {backend: libcamera, device: '1'}]\n",
     "cameras[0].device: missing key (the libcamera backend needs a camera id or index) (line 1)"},
    {"SimWithDevice", "cameras: [{backend: sim, device: /dev/video0}, {backend: sim}]\n",
     "cameras[0].device: not used by the sim backend (line 1)"},
    {"SimWithSize", "cameras: [{backend: sim}, {backend: sim, width: 640, height: 480}]\n",
     "cameras[1].width: not used by the sim backend (its images set it) (line 1)"},
    {"EmptyDevice",
     "cameras: [{backend: v4l2, device: ''}, {backend: v4l2, device: /dev/video1}]\n",
     "cameras[0].device: must not be empty (line 1)"},
    {"SameDeviceTwice",
     "cameras: [{backend: v4l2, device: /dev/video0}, {backend: v4l2, device: /dev/video0}]\n",
     "cameras[1].device: the same device as cameras[0]: '/dev/video0' (line 1)"},
    {"BadFormat",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, format: MJPG}\n  - {backend: v4l2, "
     "device: /dev/video1}\n",
     "cameras[0].format: expected GREY|Y16, got 'MJPG' (line 2)"},
    {"WidthWithoutHeight",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, width: 1032}\n  - {backend: v4l2, device: "
     "/dev/video1}\n",
     "cameras[0].height: width and height must be given together (line 2)"},
    {"HeightWithoutWidth",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, height: 776}\n  - {backend: v4l2, device: "
     "/dev/video1}\n",
     "cameras[0].width: width and height must be given together (line 2)"},
    {"WidthOutOfRange",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, width: 0, height: 5}\n  - {backend: v4l2, "
     "device: /dev/video1}\n",
     "cameras[0].width: must be in [1, 32768], got 0 (line 2)"},
    {"ExposureZero",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, exposure_us: 0}\n  - {backend: v4l2, "
     "device: /dev/video1}\n",
     "cameras[0].exposure_us: must be in [1, 10000000], got 0 (line 2)"},
    {"ExposureNotANumber",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, exposure_us: fast}\n  - {backend: v4l2, "
     "device: /dev/video1}\n",
     "cameras[0].exposure_us: expected an integer, got 'fast' (line 2)"},
    {"NegativeGain",
     "cameras:\n  - {backend: v4l2, device: /dev/video0, gain: -1}\n  - {backend: v4l2, device: "
     "/dev/video1}\n",
     "cameras[0].gain: must be in [0, 1e+06], got -1 (line 2)"},
    {"BadTrigger", "cameras: [{backend: sim, trigger: hardware}, {backend: sim}]\n",
     "cameras[0].trigger: expected free_run|external|software|central, got 'hardware' (line 1)"},
    {"ZeroFrameRate", "cameras: [{backend: sim, frame_rate_hz: 0}, {backend: sim}]\n",
     "cameras[0].frame_rate_hz: must be > 0 (line 1)"},
    {"TooFewBuffers", "cameras: [{backend: sim, buffers: 1}, {backend: sim}]\n",
     "cameras[0].buffers: must be in [2, 64], got 1 (line 1)"},
    {"ReplayTwoRecordings",
     "cameras: [{backend: replay, device: rec}, {backend: replay, device: other}]\n",
     "cameras[1].device: must name the same recording as cameras[0].device (DIR/rec) (line 1)"},
    {"ReplayMissingRecording",
     "cameras: [{backend: replay, device: nowhere}, {backend: replay, device: nowhere}]\n",
     "cameras[0].device: DIR/nowhere: not a recording folder (no such directory)"},
    {"HardwareWithoutRig", V4L2_PAIR "targets: targets.yaml\n",
     "rig: required by the v4l2 backend"},
    {"HardwareWithoutTargets", V4L2_PAIR "rig: rig.yaml\n",
     "targets: required by the v4l2 backend"},
    {"RigFileMissing", V4L2_PAIR "rig: missing.yaml\ntargets: targets.yaml\n",
     "rig: DIR/missing.yaml: cannot open: No such file or directory"},
    {"ModelFileMissing", "model: model.yaml\n",
     "model: DIR/model.yaml: cannot open: No such file or directory"},
    {"SizeDiffersFromRig",
     "cameras:\n  - {backend: v4l2, device: /dev/video0}\n"
     "  - {backend: v4l2, device: /dev/video1, width: 640, height: 480}\n" ASSETS,
     "cameras[1].width: 640x480 does not match the rig's camera 'cam1' (1032x776)"},
    {"NegativeTriggerRate", "pipeline: {trigger_rate_hz: -5}\n",
     "pipeline.trigger_rate_hz: must be in [0.01, 10000], got -5 (line 1)"},
    {"BadPacing", "pipeline: {pacing: fast}\n",
     "pipeline.pacing: expected periodic|lockstep, got 'fast' (line 1)"},
    {"RealtimeNotABool", "pipeline: {realtime: yes}\n",
     "pipeline.realtime: expected true or false, got 'yes' (line 1)"},
    {"EveryFrameNotABool", "pipeline: {every_frame: all}\n",
     "pipeline.every_frame: expected true or false, got 'all' (line 1)"},
    {"CatchUpNegative", "pipeline: {catch_up_ms: -1}\n",
     "pipeline.catch_up_ms: must be in [0, 10000], got -1 (line 1)"},
    {"CatchUpNotANumber", "pipeline: {catch_up_ms: soon}\n",
     "pipeline.catch_up_ms: expected an integer, got 'soon' (line 1)"},
    {"CpuLatencyTooLow", "pipeline: {cpu_latency_us: -2}\n",
     "pipeline.cpu_latency_us: must be in [-1, 1000000], got -2 (line 1)"},
    {"DequeueTimeout", "pipeline: {dequeue_timeout_ms: 0}\n",
     "pipeline.dequeue_timeout_ms: must be in [1, 1000], got 0 (line 1)"},
    {"UnknownStage", "pipeline: {stages: {triangulate: {cpu: 0}}}\n",
     "pipeline.stages.triangulate: unknown key (line 1); expected one of: capture, detect, "
     "identify, publish, detect0, detect1, detect2, detect3, detect4, detect5, detect6, detect7, "
     "detect8, detect9, detect10, detect11, detect12, detect13, detect14, detect15, detect16, "
     "detect17, detect18, detect19, detect20, detect21, detect22, detect23, detect24, detect25, "
     "detect26, detect27, detect28, detect29, detect30, detect31"},
    {"UnknownStageKey", "pipeline: {stages: {detect0: {core: 0}}}\n",
     "pipeline.stages.detect0.core: unknown key (line 1); expected one of: cpu, priority, "
     "ring_depth"},
    {"StageCpuTooLow", "pipeline: {stages: {detect0: {cpu: -2}}}\n",
     "pipeline.stages.detect0.cpu: must be in [-1, 1023], got -2 (line 1)"},
    {"StageCpuNotOnThisMachine", "pipeline: {stages: {detect0: {cpu: 1023}}}\n",
     "pipeline.stages.detect0.cpu: this machine has CPUs 0..NCPU, got 1023 (line 1)"},
    {"StagePriority", "pipeline: {stages: {identify: {priority: 100}}}\n",
     "pipeline.stages.identify.priority: must be in [0, 99], got 100 (line 1)"},
    {"StageRingDepth", "pipeline: {stages: {publish: {ring_depth: 1}}}\n",
     "pipeline.stages.publish.ring_depth: must be in [2, 1024], got 1 (line 1)"},
    {"CaptureRingDepth", "pipeline: {stages: {capture: {ring_depth: 4}}}\n",
     "pipeline.stages.capture.ring_depth: the capture stage has no input ring (line 1)"},
    {"UdpNotAList", "outputs: {udp: '127.0.0.1:7755'}\n",
     "outputs.udp: expected a list, got '127.0.0.1:7755' (line 1)"},
    {"UdpWithoutPort", "outputs: {udp: ['127.0.0.1']}\n",
     "outputs.udp[0]: expected HOST:PORT, got '127.0.0.1' (line 1)"},
    {"UdpBadPort", "outputs: {udp: ['a:1', 'b:70000']}\n",
     "outputs.udp[1]: port must be in 1..65535, got 'b:70000' (line 1)"},
    {"UdpVersionThree", "outputs: {udp: [{value: 'a:1', version: 3}]}\n",
     "outputs.udp[0].version: must be in [1, 2], got 3 (line 1)"},
    {"UdpMapWithoutValue", "outputs: {udp: [{version: 2}]}\n",
     "outputs.udp[0]: the map form needs a 'value' (line 1)"},
    {"UdpMapUnknownKey", "outputs: {udp: [{value: 'a:1', versoin: 2}]}\n",
     "outputs.udp[0].versoin: unknown key (line 1); expected one of: value, version, lead_ms"},
    {"UdpLeadTooLong", "outputs: {udp: [{value: 'a:1', lead_ms: 80}]}\n",
     "outputs.udp[0].lead_ms: must be in [0, 50], got 80 (line 1)"},
    {"IceoryxMapWithoutValue", "outputs: {iceoryx: {lead_ms: 5}}\n",
     "outputs.iceoryx: the map form needs a 'value' (line 1)"},
    {"IceoryxLeadNegative", "outputs: {iceoryx: {value: true, lead_ms: -1}}\n",
     "outputs.iceoryx.lead_ms: must be in [0, 50], got -1 (line 1)"},
    {"UdpMapBadValue", "outputs: {udp: [{value: 'a', version: 2}]}\n",
     "outputs.udp[0]: expected HOST:PORT, got 'a' (line 1)"},
    {"VelocityUnknownKey", "velocity: {max_gap: 100}\n",
     "velocity.max_gap: unknown key (line 1); expected one of: max_gap_ms, warmup_frames, "
     "jerk_psd_deg2_per_s5, min_angle_sd_deg, body_jerk_psd_mm2_per_s5, min_position_sd_mm"},
    {"VelocityGapZero", "velocity: {max_gap_ms: 0}\n", "velocity.max_gap_ms: must be > 0 (line 1)"},
    {"VelocityWarmup", "velocity: {warmup_frames: 0}\n",
     "velocity.warmup_frames: must be in [1, 100], got 0 (line 1)"},
    {"IceoryxNotABool", "outputs: {iceoryx: 1}\n",
     "outputs.iceoryx: expected true or false, got '1' (line 1)"},
    {"ThresholdMode", "detection: {threshold_mode: otsu}\n",
     "detection.threshold_mode: expected adaptive|fixed, got 'otsu' (line 1)"},
    {"BackgroundAboveThreshold", "detection: {threshold_dn: 30, background_dn: 30}\n",
     "detection.background_dn: background_dn must be below threshold_dn (line 1)"},
    {"AreaOrder", "detection: {min_area_px: 50, max_area_px: 10}\n",
     "detection.max_area_px: max_area_px must be >= min_area_px (line 1)"},
    {"Elongation", "detection: {max_elongation: 0.5}\n",
     "detection.max_elongation: must be in [1, 100], got 0.5 (line 1)"},
    {"SigmaNotFinite", "detection: {threshold_sigma: .nan}\n",
     "detection.threshold_sigma: not a finite number: '.nan' (line 1)"},
    {"RoiWithoutSize", "detection: {roi: {x: 4, y: 4}}\n",
     "detection.roi: width and height are required (line 1)"},
    {"RoiOutsideImage", "detection: {roi: {x: 1000, y: 0, width: 100, height: 100}}\n",
     "detection (cam0): detector: roi: outside the 1032x776 image"},
    {"DepthOrder", "stereo: {min_depth_mm: 500, max_depth_mm: 400}\n",
     "stereo.max_depth_mm: max_depth_mm must be above min_depth_mm (line 1)"},
    {"EpipolarTolerance", "stereo: {epipolar_tolerance_px: 0}\n",
     "stereo.epipolar_tolerance_px: must be > 0 (line 1)"},
    {"MinMarkers", "identification: {min_markers: 2}\n",
     "identification.min_markers: must be in [3, 64], got 2 (line 1)"},
    {"TMm", "identification: {t_mm: 0}\n", "identification.t_mm: must be > 0 (line 1)"},
    {"PartialSigmaBelowPointSigma", "identification: {partial_sigma_mm: 0.1}\n",
     "identification: identify: partial_sigma_mm: must be 0 or >= point_sigma_mm (0.2), got 0.1"},
    {"TemporalNotABool", "identification: {temporal: on}\n",
     "identification.temporal: expected true or false, got 'on' (line 1)"},
    {"LoopFramesWithHardware", V4L2_PAIR ASSETS "sim: {loop_frames: 20}\n",
     "sim.loop_frames: only used by the sim backend (cameras use v4l2) (line 6)"},
    {"LoopFramesRange", "sim: {loop_frames: 1}\n",
     "sim.loop_frames: must be in [2, 2000], got 1 (line 1)"},
    {"UnknownScene", "sim: {scene: arms}\n",
     "sim.scene: expected limbs|stalks|humanoid, got 'arms' (line 1)"},
    {"SceneWithHardware", V4L2_PAIR ASSETS "sim: {scene: stalks}\n",
     "sim.scene: only used by the sim backend (cameras use v4l2) (line 6)"},
    {"StatusInterval", "service: {status_interval_s: 0}\n",
     "service.status_interval_s: must be in [0.1, 3600], got 0 (line 1)"},
    {"StallAfterZero", "fault_injection: {stall_after_frames: 0}\n",
     "fault_injection.stall_after_frames: must be in [1, 1000000000000], got 0 (line 1)"},
    {"SectionNotAMap", "stereo: 3\n", "stereo: expected a map, got '3' (line 1)"},
    {"YamlSyntax", "pipeline: {stages: [\n", "line 2: end of sequence flow not found"},
};

class RunConfigError : public ::testing::TestWithParam<ErrorCase> {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>("cfg_err");
    std::filesystem::create_directories(dir_->file("rec/cam0"));
    std::filesystem::create_directories(dir_->file("rec/cam1"));
    auto scene = sim::make_scene(sim::SimOptions{});
    ASSERT_TRUE(scene);
    ASSERT_TRUE(save_rig(dir_->file("rig.yaml"), scene->rig));
    ASSERT_TRUE(save_targets(dir_->file("targets.yaml"), scene->targets));
    ASSERT_TRUE(save_rig(dir_->file("rec/rig.yaml"), scene->rig));
    ASSERT_TRUE(save_frames_csv(dir_->file("rec/frames.csv"), {{0, 0}, {1, 10'000'000}}));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::unique_ptr<test::TempDir> dir_;
};
std::unique_ptr<test::TempDir> RunConfigError::dir_;

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()))
    s.replace(p, from.size(), to);
  return s;
}

TEST_P(RunConfigError, IsOneLineNamingFileAndKey) {
  const ErrorCase& c = GetParam();
  const std::string file = dir_->file(std::string(c.name) + ".yaml");
  test::write_file(file, c.yaml);
  auto cfg = load_run_config(file);
  ASSERT_FALSE(cfg) << c.name << " was accepted";
  std::string expected = replace_all(c.expected, "DIR", dir_->path());
  expected = replace_all(expected, "NCPU", std::to_string(sysconf(_SC_NPROCESSORS_CONF) - 1));
  EXPECT_EQ(cfg.error().message, file + ": " + expected);
  EXPECT_EQ(cfg.error().message.find('\n'), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(All, RunConfigError, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<ErrorCase>& i) { return i.param.name; });

TEST(RunConfigFile, MissingFile) {
  auto cfg = load_run_config("/nonexistent/mocap.yaml");
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().message, "/nonexistent/mocap.yaml: cannot open: No such file or directory");
}

TEST(RunConfigFile, EmptyFile) {
  test::TempDir dir("cfg_empty");
  test::write_file(dir.file("e.yaml"), "");
  auto cfg = load_run_config(dir.file("e.yaml"));
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().message, dir.file("e.yaml") + ": empty file");
}

}  // namespace
}  // namespace mocap::config
