// Design: the compiled capacities of the whole robot (interfaces.md, "The whole robot":
// models of up to 32 bodies) as the run configuration sees them. A configuration whose
// targets.yaml has kMaxBodies = 32 bodies and whose model.yaml chains them with 31
// calibrated ball joints loads (the tracker is built once: identification, joint angles
// and chain tracking all take it); 33 bodies, a body of 17 markers or an
// identification.max_points beyond kMaxPoints are one line naming the configuration,
// the key and the offending file.
#include <gtest/gtest.h>

#include <string>

#include "config/run_config.h"
#include "config/tracking_assets.h"
#include "formats/joints_yaml.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::config {
namespace {

// `bodies` bodies of `markers` markers each, every target of its own geometry (no two
// alike: identification has nothing to warn about).
TargetSet make_targets(int bodies, int markers) {
  TargetSet t;
  t.marker_diameter_mm = 12.0;
  for (int b = 0; b < bodies; ++b) {
    MarkerTarget m;
    m.name = "body" + std::to_string(b);
    for (int k = 0; k < markers; ++k) {
      const double r = 30.0 + 7.0 * k + 1.3 * b;
      m.markers_body.emplace_back(r * (k % 3 == 0), r * (k % 3 == 1) + 2.0 * k,
                                  r * (k % 3 == 2) + 0.5 * b);
    }
    t.bodies.push_back(std::move(m));
  }
  return t;
}

// A chain body0 - body1 - ... - body{n-1} of calibrated ball joints.
JointModel make_chain_model(int bodies) {
  JointModel model;
  for (int b = 1; b < bodies; ++b) {
    JointSpec j;
    j.name = "joint" + std::to_string(b);
    j.type = JointType::kBall;
    j.parent = "body" + std::to_string(b - 1);
    j.child = "body" + std::to_string(b);
    j.calibrated = true;
    j.center_parent = Vec3(0.0, 0.0, 120.0);
    j.center_child = Vec3(0.0, 0.0, -40.0);
    model.joints.push_back(j);
  }
  return model;
}

class Capacity : public ::testing::Test {
 protected:
  void SetUp() override {
    auto scene = sim::make_scene(sim::SimOptions{});
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_TRUE(save_rig(dir.file("rig.yaml"), scene->rig));
  }
  // A v4l2 pair configuration (cameras are not opened by load_run_config) on rig.yaml,
  // `targets` and, if given, `model`, plus `extra` YAML.
  std::string write_config(const std::string& targets, const std::string& model = "",
                           const std::string& extra = "") {
    const std::string path = dir.file("m.yaml");
    test::write_file(path,
                     "cameras:\n  - {backend: v4l2, device: /dev/video0}\n"
                     "  - {backend: v4l2, device: /dev/video1}\n"
                     "rig: rig.yaml\ntargets: " +
                         targets + "\n" + (model.empty() ? "" : "model: " + model + "\n") + extra);
    return path;
  }
  test::TempDir dir{"cfg_capacity"};
};

TEST_F(Capacity, ThirtyTwoBodiesWithAChainModelLoad) {
  ASSERT_EQ(kMaxBodies, 32);
  const TargetSet targets = make_targets(kMaxBodies, kMaxMarkers);
  ASSERT_TRUE(save_targets(dir.file("targets.yaml"), targets));
  ASSERT_TRUE(save_model(dir.file("model.yaml"), make_chain_model(kMaxBodies)));
  auto cfg = load_run_config(write_config("targets.yaml", "model.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto assets = load_tracking_assets(*cfg, nullptr, nullptr, nullptr);
  ASSERT_TRUE(assets) << assets.error().message;
  EXPECT_EQ(assets->targets.bodies.size(), 32u);
  ASSERT_TRUE(assets->model.has_value());
  EXPECT_EQ(assets->model->joints.size(), 31u);
  // The tracker itself takes the whole model (load_run_config built it once too).
  auto proc = FrameProcessor::create(assets->rig, assets->targets, &*assets->model, cfg->tracker);
  ASSERT_TRUE(proc) << proc.error().message;
  EXPECT_EQ(proc->make_output().poses.count, 32);
}

TEST_F(Capacity, ThirtyThreeBodiesAreOneLineNamingTheTargetsFile) {
  ASSERT_TRUE(save_targets(dir.file("t33.yaml"), make_targets(kMaxBodies + 1, 4)));
  const std::string path = write_config("t33.yaml");
  auto cfg = load_run_config(path);
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().message, path + ": targets: " + dir.file("t33.yaml") +
                                     ": bodies: 33 bodies, at most 32 (the compiled capacity "
                                     "kMaxBodies)");
  EXPECT_EQ(cfg.error().message.find('\n'), std::string::npos);
}

TEST_F(Capacity, SeventeenMarkersAreOneLineNamingTheBody) {
  TargetSet t = make_targets(2, 4);
  t.bodies[1] = make_targets(1, kMaxMarkers + 1).bodies[0];
  t.bodies[1].name = "hand";
  ASSERT_TRUE(save_targets(dir.file("t17.yaml"), t));
  const std::string path = write_config("t17.yaml");
  auto cfg = load_run_config(path);
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().message, path + ": targets: " + dir.file("t17.yaml") +
                                     ": bodies[1] 'hand': 17 markers, at most 16 (the compiled "
                                     "capacity kMaxMarkers)");
}

TEST_F(Capacity, MaxPointsIsAKeyBoundedByTheCompiledCapacity) {
  ASSERT_TRUE(save_targets(dir.file("targets.yaml"), make_targets(2, 4)));
  auto cfg =
      load_run_config(write_config("targets.yaml", "", "identification: {max_points: 300}\n"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->tracker.identify.max_points, 300);
  const std::string path = write_config(
      "targets.yaml", "", "identification: {max_points: " + std::to_string(kMaxPoints + 1) + "}\n");
  auto bad = load_run_config(path);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message,
            path + ": identification.max_points: must be in [3, 512], got 513 (line 6)");
}

}  // namespace
}  // namespace mocap::config
