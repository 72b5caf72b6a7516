// Design: the mapping of the run configuration onto the pipeline and the HAL: stage
// names and overrides, command-line overrides, a sim setup built end to end from a
// configuration (cameras configured as asked, buffers sized from the ring depth), and
// fault_injection.stall_after_frames: camera 0 in a hal::FaultCamera (N frames, then
// timeouts only).
#include "pipeline/service/live_setup.h"

#include <gtest/gtest.h>

#include <string>

#include "hal/fault_camera.h"
#include "tests/service/tiny_recording.h"
#include "tests/support/test_support.h"

namespace mocap::service {
namespace {

TEST(LiveSetup, StageNamesMatchThePipelineTable) {
  for (std::size_t i = 0; i < config::kStageCount; ++i) {
    EXPECT_EQ(std::string("mocap-") + config::kStageNames[i], pipeline::kDefaultStages[i].name);
  }
}

TEST(LiveSetup, StageOverridesOnTopOfTheDefaultTable) {
  config::RunConfig cfg = config::default_run_config();
  cfg.pipeline.stages[2].cpu = 0;  // identify
  cfg.pipeline.stages[2].ring_depth = 8;
  cfg.pipeline.stages[3].priority = 0;           // publish
  cfg.pipeline.detect_camera[1].ring_depth = 6;  // detect1 only
  cfg.pipeline.pacing = TriggerPacing::kLockstep;
  cfg.pipeline.trigger_rate_hz = 250.0;
  const pipeline::PipelineOptions o = pipeline_options(cfg);
  using pipeline::StageKind;
  EXPECT_EQ(o.stages[StageKind::kIdentify].cpu, 0);
  EXPECT_EQ(o.stages[StageKind::kIdentify].ring_depth, 8u);
  EXPECT_EQ(o.stages[StageKind::kIdentify].fifo_priority,
            pipeline::kDefaultStages[2].fifo_priority);
  EXPECT_EQ(o.stages[StageKind::kPublish].fifo_priority, 0);
  EXPECT_EQ(o.stages[StageKind::kDetect].cpu, pipeline::kDefaultStages[1].cpu);
  EXPECT_EQ(o.stages.detect[1].ring_depth, 6u);
  EXPECT_EQ(o.stages.detect[0].ring_depth, 0u);  // unset: the rule's
  EXPECT_EQ(o.pacing, pipeline::TriggerPacing::kLockstep);
  EXPECT_DOUBLE_EQ(o.trigger_rate_hz, 250.0);
}

TEST(LiveSetup, CommandLineOverridesTheFile) {
  test::TempDir dir("svc_cli");
  test::write_file(dir.file("m.yaml"),
                   "outputs: {udp: ['10.0.0.9:9000'], iceoryx: true}\n"
                   "pipeline: {trigger_rate_hz: 50}\n");
  auto same = resolve_run_config(dir.file("m.yaml"), CliOverrides{});
  ASSERT_TRUE(same) << same.error().message;
  EXPECT_EQ(same->outputs.udp[0], "10.0.0.9:9000");
  CliOverrides cli;
  cli.udp = "127.0.0.1:9999";
  cli.rate_hz = 120.0;
  cli.no_iceoryx = true;
  cli.no_realtime = true;
  auto cfg = resolve_run_config(dir.file("m.yaml"), cli);
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->outputs.udp, std::vector<std::string>{"127.0.0.1:9999"});
  EXPECT_DOUBLE_EQ(cfg->pipeline.trigger_rate_hz, 120.0);
  EXPECT_FALSE(cfg->outputs.iceoryx);
  EXPECT_FALSE(cfg->pipeline.realtime);
  cli.udp = "nohost";
  auto bad = resolve_run_config(dir.file("m.yaml"), cli);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "--udp: expected HOST:PORT, got 'nohost'");
  // The flags are checked by the configuration's own checks (the same ranges as the keys).
  cli.udp.reset();
  cli.rate_hz = 0.0;
  auto slow = resolve_run_config(dir.file("m.yaml"), cli);
  ASSERT_FALSE(slow);
  EXPECT_EQ(slow.error().message, "--rate: must be in [0.01, 10000] Hz, got 0");
  cli.rate_hz = 10000.0;  // the largest rate the file's key accepts is a valid flag too
  EXPECT_TRUE(resolve_run_config(dir.file("m.yaml"), cli));
  cli.loop_frames = 1;
  auto short_loop = resolve_run_config(dir.file("m.yaml"), cli);
  ASSERT_FALSE(short_loop);
  EXPECT_EQ(short_loop.error().message, "--loop-frames: must be in 2..2000, got 1");
  cli.loop_frames.reset();
  cli.multicast_ttl = 300;  // checked by the udp output, as the file's option would be
  EXPECT_FALSE(resolve_run_config(dir.file("m.yaml"), cli));
  auto missing = resolve_run_config(dir.file("absent.yaml"), CliOverrides{});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("absent.yaml: cannot open"), std::string::npos);
}

TEST(LiveSetup, RegistryOutputsFromTheFileAndTheFlags) {
  test::TempDir dir("svc_outputs");
  test::write_file(dir.file("o.yaml"), "outputs:\n  udp: []\n  iceoryx: false\n  ros2: false\n");
  auto cfg = resolve_run_config(dir.file("o.yaml"), CliOverrides{});
  ASSERT_TRUE(cfg) << cfg.error().message;
  ASSERT_EQ(cfg->outputs.more.size(), 1u);
  EXPECT_EQ(cfg->outputs.more[0].name, "ros2");
  EXPECT_EQ(cfg->outputs.more[0].values, std::vector<std::string>{"false"});
  CliOverrides cli;
  cli.outputs.emplace_back("ros2", "true");  // --ros2 replaces outputs.ros2
  auto on = resolve_run_config(dir.file("o.yaml"), cli);
  ASSERT_TRUE(on) << on.error().message;
  ASSERT_EQ(on->outputs.more.size(), 1u);
  EXPECT_EQ(on->outputs.more[0].values, std::vector<std::string>{"true"});
  const auto req = output_requests(*on, cli);
  ASSERT_EQ(req.size(), 3u);  // udp, iceoryx, ros2
  EXPECT_EQ(req[0].name, "udp");
  EXPECT_TRUE(req[0].values.empty());
  EXPECT_EQ(req[2].name, "ros2");
  EXPECT_EQ(req[2].where, "--ros2");

  test::write_file(dir.file("bad.yaml"), "outputs:\n  udp: []\n  nosuch: 1\n");
  auto bad = resolve_run_config(dir.file("bad.yaml"), CliOverrides{});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message.rfind(dir.file("bad.yaml") +
                                          ": outputs.nosuch (line 3): unknown output 'nosuch' "
                                          "(known: udp, iceoryx",
                                      0),
            0u)
      << bad.error().message;
  EXPECT_EQ(check_config_command(dir.file("bad.yaml")), 1);
  // The map form: `value` plus options, checked against the output's option keys.
  // error_of(file, ros2's value): the one-line error of that configuration ("" if none).
  const auto error_of = [&](const std::string& file, const std::string& ros2) {
    test::write_file(dir.file(file), "outputs:\n  ros2: " + ros2 + "\n");
    auto r = resolve_run_config(dir.file(file), CliOverrides{});
    return r ? std::string() : r.error().message;
  };
  EXPECT_EQ(error_of("map.yaml", "{a: 1}"),
            dir.file("map.yaml") + ": outputs.ros2: the map form needs a 'value' (line 2)");
  test::write_file(dir.file("opt.yaml"), "outputs:\n  ros2: {value: false, domain_id: 7}\n");
  auto opt = resolve_run_config(dir.file("opt.yaml"), CliOverrides{});
  ASSERT_TRUE(opt) << opt.error().message;
  ASSERT_EQ(opt->outputs.more.size(), 1u);
  EXPECT_EQ(opt->outputs.more[0].values, std::vector<std::string>{"false"});
  using Options = std::vector<std::pair<std::string, std::string>>;
  EXPECT_EQ(opt->outputs.more[0].options, (Options{{"domain_id", "7"}}));
  auto with_flag = resolve_run_config(dir.file("opt.yaml"), cli);  // --ros2 keeps domain_id
  ASSERT_TRUE(with_flag) << with_flag.error().message;
  EXPECT_EQ(output_requests(*with_flag, cli)[2].options, (Options{{"domain_id", "7"}}));
  EXPECT_EQ(error_of("typo.yaml", "{value: false, domain: 7}"),
            dir.file("typo.yaml") +
                ": outputs.ros2 (line 2): domain: unknown option (known: domain_id frame_id "
                "world_rotation)");
  // The 2027-01 options: a frame id and a world rotation, checked with one line naming it.
  test::write_file(
      dir.file("rot.yaml"),
      "outputs:\n  ros2: {value: true, frame_id: odom, world_rotation: \"0 0 0 1\"}\n");
  auto rot = resolve_run_config(dir.file("rot.yaml"), CliOverrides{});
  ASSERT_TRUE(rot) << rot.error().message;
  EXPECT_EQ(rot->outputs.more[0].options,
            (Options{{"frame_id", "odom"}, {"world_rotation", "0 0 0 1"}}));
  EXPECT_EQ(error_of("enu.yaml", "{value: true, world_rotation: enu}"),
            dir.file("enu.yaml") +
                ": outputs.ros2 (line 2): world_rotation: expected identity, camera_to_z_up, "
                "y_up_to_z_up or a unit quaternion 'qw qx qy qz', got 'enu'");
  const std::string deep = error_of("deep.yaml", "{value: false, domain_id: [1]}");
  EXPECT_NE(deep.find("outputs.ros2.domain_id: expected a value, got"), std::string::npos) << deep;
}

TEST(LiveSetup, ReplayCamerasConfiguredFromTheFile) {
  test::TempDir dir("svc_setup");
  test::write_tiny_recording(dir.file("rec"), 4);
  test::write_file(dir.file("m.yaml"), test::tiny_replay_config(dir.file("rec"), ""));
  auto cfg = config::load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  cfg->cameras[0].buffers = 9;
  cfg->pipeline.detect_camera[1].ring_depth = 5;  // detect1
  auto setup = LiveSetup::create(*cfg, nullptr);
  ASSERT_TRUE(setup) << setup.error().message;
  const auto cams = (*setup)->cameras();
  EXPECT_EQ(cams[0]->config().buffer_count, 9);
  EXPECT_EQ(cams[1]->config().buffer_count, 8);  // detect1 ring depth + 3
  EXPECT_EQ(cams[0]->config().trigger, hal::TriggerMode::kSoftware);
  EXPECT_EQ(cams[0]->config().width, 64);
  EXPECT_EQ(cams[0]->state(), hal::CameraState::kConfigured);
  EXPECT_EQ((*setup)->options().stages.detect[1].ring_depth, 5u);
  FrameProcessor proc = (*setup)->take_processor();
  EXPECT_FALSE(proc.has_model());  // no model in the file: poses only
}

TEST(LiveSetup, HardwareWithoutRigIsAConfigurationError) {
  config::RunConfig cfg = config::default_run_config();
  cfg.cameras[0].backend = cfg.cameras[1].backend = config::CameraBackend::kV4l2;
  cfg.cameras[0].device = "/dev/null/video0";
  cfg.cameras[1].device = "/dev/null/video1";
  auto no_rig = LiveSetup::create(cfg, nullptr);
  ASSERT_FALSE(no_rig);
  EXPECT_EQ(no_rig.error().message, "mocap run: rig: required by the v4l2 backend");
}

TEST(LiveSetup, StallAfterFramesWrapsCameraZeroInAFaultCamera) {
  test::TempDir dir("svc_stallcam");
  test::write_tiny_recording(dir.file("rec"), 8);
  test::write_file(dir.file("m.yaml"), test::tiny_replay_config(dir.file("rec"), ""));
  auto cfg = config::load_run_config(dir.file("m.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  cfg->faults.stall_after_frames = 3;
  auto setup = LiveSetup::create(*cfg, nullptr);
  ASSERT_TRUE(setup) << setup.error().message;
  const auto cams = (*setup)->cameras();
  auto* cam = dynamic_cast<hal::FaultCamera*>(cams[0]);
  ASSERT_NE(cam, nullptr);
  EXPECT_EQ(dynamic_cast<hal::FaultCamera*>(cams[1]), nullptr);  // camera 0 only
  EXPECT_EQ(cam->config().trigger, hal::TriggerMode::kSoftware);
  ASSERT_TRUE(cam->start());
  int delivered = 0, timeouts = 0;
  for (int i = 0; i < 6; ++i) {
    ASSERT_EQ(cam->trigger(), hal::CameraStatus::kOk);
    hal::Frame f;
    const hal::CameraStatus st = cam->dequeue(f, 20);
    if (st == hal::CameraStatus::kOk) {
      ++delivered;
      EXPECT_EQ(f.sequence, static_cast<std::uint64_t>(i));
      EXPECT_EQ(cam->release(f), hal::CameraStatus::kOk);
    } else {
      EXPECT_EQ(st, hal::CameraStatus::kTimeout);
      ++timeouts;
    }
  }
  EXPECT_EQ(delivered, 3);
  EXPECT_EQ(timeouts, 3);
  EXPECT_EQ(cam->injected(hal::Fault::kStall), 3u);
  EXPECT_EQ(cam->counters().frames.get(), 3u);  // the inner camera was not asked again
  cam->stop();
  EXPECT_EQ(cam->state(), hal::CameraState::kConfigured);
}

}  // namespace
}  // namespace mocap::service
