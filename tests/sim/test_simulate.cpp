// Recording tests: what write_simulated_recording writes loads back with the formats
// readers, the ground-truth angles agree with the ground-truth poses, and the output
// does not depend on the number of threads.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "core/rotation.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::sim {
namespace {

namespace fs = std::filesystem;

TEST(SimRecording, LoadsBackAndGroundTruthIsConsistent) {
  test::TempDir dir("sim_rec");
  SimOptions opt;
  opt.frames = 12;
  opt.motion = MotionKind::kPoses;
  opt.poses = 4;
  opt.stray = 3;
  auto sum = write_simulated_recording(opt, dir.path());
  ASSERT_TRUE(sum.ok()) << sum.error().message;
  EXPECT_EQ(sum->frames, 12);
  const int markers_per_frame = make_scene(opt)->marker_count();  // 16 (limbs layout)
  EXPECT_EQ(markers_per_frame, 16);
  EXPECT_EQ(sum->marker_views, 12 * markers_per_frame * 2);

  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  ASSERT_EQ(rec->frames().size(), 12u);
  EXPECT_EQ(rec->frames()[1].timestamp_ns, 10000000);
  Image img;
  auto lf = rec->load_frame(1, 11, img);
  ASSERT_TRUE(lf.ok()) << lf.error().message;
  EXPECT_EQ(*lf, FrameLoad::kOk);
  EXPECT_EQ(img.width(), 1032);

  auto targets = load_targets(dir.file("targets.yaml"));
  ASSERT_TRUE(targets.ok()) << targets.error().message;
  EXPECT_EQ(targets->bodies.size(), 3u);
  auto joints = load_joints(dir.file("joints.yaml"), *targets);
  ASSERT_TRUE(joints.ok()) << joints.error().message;
  EXPECT_EQ(joints->joints.size(), 2u);
  auto model = load_model(dir.file("gt/model_true.yaml"), *targets);
  ASSERT_TRUE(model.ok()) << model.error().message;

  auto poses = read_poses_csv(dir.file("gt/poses.csv"));
  ASSERT_TRUE(poses.ok()) << poses.error().message;
  ASSERT_EQ(poses->size(), 36u);
  auto angles = read_angles_csv(dir.file("gt/angles.csv"));
  ASSERT_TRUE(angles.ok()) << angles.error().message;
  ASSERT_EQ(angles->size(), 24u);
  // Recompute every joint angle from the ground-truth poses and the true model.
  for (const AngleRow& a : *angles) {
    const JointSpec& j = model->joints[static_cast<std::size_t>(model->index_of(a.joint))];
    Iso3 Tp = Iso3::Identity(), Tc = Iso3::Identity();
    for (const PoseRow& p : *poses) {
      if (p.frame != a.frame) continue;
      if (p.body == j.parent) Tp = make_iso(p.q_world_body.toRotationMatrix(), p.t_world_body);
      if (p.body == j.child) Tc = make_iso(p.q_world_body.toRotationMatrix(), p.t_world_body);
    }
    const Vec3 deg = joint_angles_rad(j, Tp, Tc) * (180.0 / std::numbers::pi);
    EXPECT_LT((deg - a.angles_deg).cwiseAbs().maxCoeff(), 1e-3) << a.joint << " frame " << a.frame;
    const Quat q = canonical_quat(Tp.linear().transpose() * Tc.linear());
    EXPECT_LT(q.angularDistance(a.q_parent_child), 1e-6);
    if (j.type == JointType::kBall) {
      const Mat3 R = euler_xyz_to_rotation(a.angles_deg * (std::numbers::pi / 180.0));
      EXPECT_LT((R - a.q_parent_child.toRotationMatrix()).norm(), 1e-5);
    }
  }
  // Ground-truth marker table: one row per marker and frame.
  const std::string markers = test::read_file(dir.file("gt/markers.csv"));
  EXPECT_EQ(markers.rfind("frame,body,marker,x,y,z,u0,v0,vis0,u1,v1,vis1", 0), 0u);
  EXPECT_EQ(test::line_count(markers), 1 + 12 * markers_per_frame);
  EXPECT_TRUE(fs::exists(dir.file("gt/strays.csv")));
  EXPECT_EQ(test::line_count(test::read_file(dir.file("gt/segments.csv"))), 1 + 4);
}

TEST(SimRecording, ThreadsDoNotChangeTheOutput) {
  test::TempDir a("sim_t1"), b("sim_t2");
  SimOptions opt;
  opt.frames = 3;
  opt.dropout = 0.2;
  opt.stray = 4;
  opt.threads = 1;
  ASSERT_TRUE(write_simulated_recording(opt, a.path()).ok());
  opt.threads = 2;
  ASSERT_TRUE(write_simulated_recording(opt, b.path()).ok());
  for (const char* f : {"cam0/000002.pgm", "cam1/000002.pgm", "gt/markers.csv", "gt/strays.csv"}) {
    EXPECT_EQ(test::read_file(a.file(f)), test::read_file(b.file(f))) << f;
  }
}

}  // namespace
}  // namespace mocap::sim
