// Tests of chain tracking on the whole-body humanoid (15 bodies, 14 joints): a hand and
// its forearm with 2 markers each solved through two levels under the found upper arm;
// joints of two found bodies refitted with the joint centre and rejected when their
// poses disagree with the joint; no allocation per frame; the partial-marker noise
// derivation (partial_centroid_shift against a numerically integrated cut disc); and a
// short 6-camera rendered recording against the ground truth (coverage of the
// observable joints, no angle more than 2 deg off). Kept small: CI runs it under ASan.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "formats/joints_yaml.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "identify/consistency.h"
#include "identify/rigid_fit.h"
#include "sim/scene.h"
#include "tests/support/alloc_counter.h"
#include "tests/track/track_fixture.h"
#include "track/chain_solver.h"
#include "track/frame_processor.h"
#include "track/marker_shape.h"
#include "track/offline_tracker.h"

namespace mocap {
namespace {

constexpr std::int64_t kHumanoidDt = 10'000'000;  // 100 fps

struct Humanoid {
  sim::SimScene scene;
  ChainSolver solver;
  std::mt19937 rng{11};

  static Humanoid make() {
    sim::SceneOptions options;
    options.kind = sim::SceneKind::kHumanoid;
    auto scene = sim::build_scene(options);
    EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
    auto model = ChainModel::create(scene->joints_true, scene->targets);
    EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message);
    auto solver = ChainSolver::create(std::move(model).value(), ChainConfig{});
    EXPECT_TRUE(solver.ok()) << (solver.ok() ? "" : solver.error().message);
    return Humanoid{std::move(scene).value(), std::move(solver).value()};
  }
  int body(const char* name) const { return scene.targets.index_of(name); }
  int joint(const char* name) const { return scene.joints_true.index_of(name); }

  sim::SceneState state(double bend) const {
    sim::JointConfig jc = sim::make_config(scene);
    for (Vec3& q : jc.q_rad) q = Vec3(0.2, -0.15, 0.1) * bend;
    sim::SceneState st = sim::make_state(scene);
    sim::apply_config(scene, jc, st);
    return st;
  }

  // Noisy points of the first visible[b] markers of every body (all when < 0); bodies
  // with found[b] get their exact pose and labels, as identification reports them.
  void frame(const sim::SceneState& st, const std::vector<int>& visible,
             const std::vector<bool>& found, std::vector<MeasuredPoint>& pts, BodyPoses& poses) {
    std::normal_distribution<double> n(0.0, 0.05);
    pts.clear();
    poses = BodyPoses{};
    poses.count = static_cast<int>(scene.targets.bodies.size());
    for (std::size_t b = 0; b < scene.targets.bodies.size(); ++b) {
      BodyPose& bp = poses.bodies[b];
      bp.point_index_of_marker.fill(-1);
      const auto& markers = scene.targets.bodies[b].markers_body;
      const int k = visible[b] < 0 ? static_cast<int>(markers.size()) : visible[b];
      for (int m = 0; m < k; ++m) {
        MeasuredPoint p;
        p.X_world = st.T_world_body[b] * markers[static_cast<std::size_t>(m)] +
                    Vec3(n(rng), n(rng), n(rng));
        p.blob_index = {static_cast<std::int16_t>(pts.size()),
                        static_cast<std::int16_t>(pts.size())};
        if (found[b])
          bp.point_index_of_marker[static_cast<std::size_t>(m)] =
              static_cast<std::int16_t>(pts.size());
        pts.push_back(p);
      }
      bp.found = found[b];
      if (bp.found) bp.T_world_body = st.T_world_body[b], ++poses.found;
    }
  }
  void accept(BodyPoses poses, const ChainResult& r, std::int64_t t) {
    for (std::size_t b = 0; b < scene.targets.bodies.size(); ++b) {
      if (!r.chain_body[b] && !r.refined_body[b]) continue;
      poses.bodies[b].found = true;
      poses.bodies[b].T_world_body = r.T_world_body[b];
    }
    solver.remember(poses, t);
  }
};

double humanoid_rot_err_deg(const Mat3& A, const Mat3& B) {
  return Eigen::AngleAxisd(A.transpose() * B).angle() * 180.0 / std::numbers::pi;
}

TEST(HumanoidChain, HandUnderChainSolvedForearm) {
  Humanoid h = Humanoid::make();
  const std::size_t nb = h.scene.targets.bodies.size();
  const int fore = h.body("forearm_l"), hand = h.body("hand_l");
  ASSERT_GE(fore, 0);
  ASSERT_GE(hand, 0);
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const sim::SceneState st0 = h.state(1.0);
  h.frame(st0, std::vector<int>(nb, -1), std::vector<bool>(nb, true), pts, poses);
  h.solver.solve(pts.data(), static_cast<int>(pts.size()), kHumanoidDt, poses, r);
  h.accept(poses, r, kHumanoidDt);
  for (int j = 0; j < h.solver.model().joint_count(); ++j)
    EXPECT_EQ(r.joints[static_cast<std::size_t>(j)].solved_by, client::SolvedBy::kPoses) << j;

  // Next frame: the forearm and the hand show 2 markers each; neither is found.
  const sim::SceneState st1 = h.state(1.05);
  std::vector<int> visible(nb, -1);
  std::vector<bool> found(nb, true);
  visible[static_cast<std::size_t>(fore)] = 2;
  visible[static_cast<std::size_t>(hand)] = 2;
  found[static_cast<std::size_t>(fore)] = false;
  found[static_cast<std::size_t>(hand)] = false;
  h.frame(st1, visible, found, pts, poses);
  h.solver.solve(pts.data(), static_cast<int>(pts.size()), 2 * kHumanoidDt, poses, r);
  ASSERT_TRUE(r.chain_body[static_cast<std::size_t>(fore)]);
  ASSERT_TRUE(r.chain_body[static_cast<std::size_t>(hand)]);
  EXPECT_EQ(r.joints[static_cast<std::size_t>(h.joint("elbow_l"))].solved_by,
            client::SolvedBy::kChain);
  EXPECT_EQ(r.joints[static_cast<std::size_t>(h.joint("wrist_l"))].solved_by,
            client::SolvedBy::kChain);
  EXPECT_LT(humanoid_rot_err_deg(r.T_world_body[static_cast<std::size_t>(hand)].linear(),
                                 st1.T_world_body[static_cast<std::size_t>(hand)].linear()),
            0.5);
}

// A partial point that is only a sliver of a ball (sigma 8 mm: its gate wider than the
// hand's marker spacing) identifies no marker: it must not tie with the whole point of
// a marker and leave that marker unlabelled as ambiguous (6 cameras smooth, frame 16:
// the hand then rested on two biased partial points, wrist_l 1.95 deg off).
TEST(HumanoidChain, AnUncertainPartialPointDoesNotHideAWholeOne) {
  Humanoid h = Humanoid::make();
  const std::size_t nb = h.scene.targets.bodies.size();
  const auto hand = static_cast<std::size_t>(h.body("hand_l"));
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const sim::SceneState st = h.state(1.0);
  std::vector<bool> found(nb, true);
  found[hand] = false;
  h.frame(st, std::vector<int>(nb, -1), found, pts, poses);
  // The hand's marker 2 (points in body order); the sliver lies 6 mm from it, on its locus.
  int whole2 = 2;
  for (std::size_t b = 0; b < hand; ++b)
    whole2 += static_cast<int>(h.scene.targets.bodies[b].markers_body.size());
  const auto& markers = h.scene.targets.bodies[hand].markers_body;
  const Vec3 centre = st.T_world_body[hand] * h.solver.model().joint(h.joint("wrist_l")).c_child;
  const Vec3 x2 = pts[static_cast<std::size_t>(whole2)].X_world;
  const Vec3 tangent = (x2 - centre).unitOrthogonal();
  MeasuredPoint sliver;
  sliver.X_world = centre + (x2 + 6.0 * tangent - centre).normalized() * (x2 - centre).norm();
  sliver.blob_index = {static_cast<std::int16_t>(pts.size()),
                       static_cast<std::int16_t>(pts.size())};
  sliver.partial = true;
  pts.push_back(sliver);
  ASSERT_EQ(markers.size(), 4u);
  std::vector<double> partial_sigma(pts.size(), 0.0);
  partial_sigma.back() = 8.0;
  h.solver.solve(pts.data(), static_cast<int>(pts.size()), kHumanoidDt, poses, r,
                 partial_sigma.data());
  ASSERT_TRUE(r.chain_body[hand]);
  EXPECT_EQ(r.point_index_of_marker[hand][2], whole2);
  EXPECT_EQ(r.markers[hand], 4);
}

TEST(HumanoidChain, PosesThatDisagreeWithTheJointAreNotValid) {
  Humanoid h = Humanoid::make();
  const std::size_t nb = h.scene.targets.bodies.size();
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const sim::SceneState st = h.state(1.0);
  h.frame(st, std::vector<int>(nb, -1), std::vector<bool>(nb, true), pts, poses);
  // The thigh's pose rotated by 2.6 deg about its own markers' centroid: its markers
  // still fit it (as a biased pose would), but not the hip.
  const int thigh = h.body("thigh_l");
  BodyPose& bp = poses.bodies[static_cast<std::size_t>(thigh)];
  Vec3 c = Vec3::Zero();
  for (const Vec3& m : h.scene.targets.bodies[static_cast<std::size_t>(thigh)].markers_body) c += m;
  c /= static_cast<double>(
      h.scene.targets.bodies[static_cast<std::size_t>(thigh)].markers_body.size());
  const Vec3 c_w = bp.T_world_body * c;
  const Mat3 dR =
      Eigen::AngleAxisd(2.6 * std::numbers::pi / 180.0, Vec3::UnitX()).toRotationMatrix();
  bp.T_world_body.linear() = dR * bp.T_world_body.linear();
  bp.T_world_body.translation() = dR * (bp.T_world_body.translation() - c_w) + c_w;
  for (const std::int16_t p : bp.point_index_of_marker) {
    if (p < 0) continue;
    MeasuredPoint& q = pts[static_cast<std::size_t>(p)];
    q.X_world = dR * (q.X_world - c_w) + c_w;
  }
  h.solver.solve(pts.data(), static_cast<int>(pts.size()), kHumanoidDt, poses, r);
  const auto& hip = r.joints[static_cast<std::size_t>(h.joint("hip_l"))];
  EXPECT_TRUE(hip.inconsistent);
  EXPECT_EQ(hip.solved_by, client::SolvedBy::kNone);
  EXPECT_GE(h.solver.counters().pose_rejects, 1u);
  // The other joints keep their angles.
  EXPECT_EQ(r.joints[static_cast<std::size_t>(h.joint("hip_r"))].solved_by,
            client::SolvedBy::kPoses);
}

// A found body's pose fitted on one point 1.6 mm off (a marker seen whole, biased by a
// merged view): its own fit absorbs most of the error along the directions its markers'
// spread leaves loose, so its residual stays small, but the joint does not. The refit with
// the joint's evidence (centre; a hinge's axis too) tests each marker alone and drops it.
TEST(HumanoidChain, AMarkerBiasedWithinItsOwnFitIsDroppedByTheJoint) {
  for (const char* name : {"forearm_l", "hand_l"}) {
    SCOPED_TRACE(name);
    Humanoid h = Humanoid::make();
    const std::size_t nb = h.scene.targets.bodies.size();
    std::vector<MeasuredPoint> pts;
    BodyPoses poses;
    ChainResult r;
    const sim::SceneState st = h.state(1.0);
    h.frame(st, std::vector<int>(nb, -1), std::vector<bool>(nb, true), pts, poses);
    const auto b = static_cast<std::size_t>(h.body(name));
    BodyPose& bp = poses.bodies[b];
    const auto& markers = h.scene.targets.bodies[b].markers_body;
    // Bias marker 0 across the body's long axis (the first to the last marker) and
    // across its lever from the centroid: the rotation about that axis absorbs it.
    Vec3 c = Vec3::Zero();
    for (const Vec3& m : markers) c += m;
    c /= static_cast<double>(markers.size());
    const Vec3 along = (markers.back() - markers.front()).normalized();
    const Vec3 across = along.cross(markers[0] - c).normalized();
    MeasuredPoint& biased = pts[static_cast<std::size_t>(bp.point_index_of_marker[0])];
    biased.X_world += st.T_world_body[b].linear() * (1.6 * across);
    // The pose identification reports: the least-squares fit on every matched point.
    FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
    for (std::size_t k = 0; k < markers.size(); ++k) {
      src.col(static_cast<Eigen::Index>(k)) = markers[k];
      dst.col(static_cast<Eigen::Index>(k)) =
          pts[static_cast<std::size_t>(bp.point_index_of_marker[k])].X_world;
    }
    const RigidFit fit = fit_rigid(src, dst, static_cast<int>(markers.size()));
    bp.T_world_body = fit.T_dst_src;
    // Its residual passes identification's test (sigma 0.2 mm, 3m - 6 dof)...
    ASSERT_LE(fit.sum_sq_mm2,
              0.04 * chi2_quantile(3 * static_cast<int>(markers.size()) - 6, 0.9999));
    const double before =
        humanoid_rot_err_deg(bp.T_world_body.linear(), st.T_world_body[b].linear());
    ASSERT_GT(before, 0.3);
    // ...but the joint names it.
    h.solver.solve(pts.data(), static_cast<int>(pts.size()), kHumanoidDt, poses, r);
    ASSERT_TRUE(r.refined_body[b]);
    EXPECT_EQ(r.point_index_of_marker[b][0], -1);
    EXPECT_LT(humanoid_rot_err_deg(r.T_world_body[b].linear(), st.T_world_body[b].linear()), 0.1)
        << "identified pose " << before << " deg off";
    const auto& joint = r.joints[static_cast<std::size_t>(
        h.scene.joints_true.index_of(std::string(name) == "hand_l" ? "wrist_l" : "elbow_l"))];
    EXPECT_EQ(joint.solved_by, client::SolvedBy::kPoses);
  }
}

TEST(HumanoidChain, SteadyStateAllocatesNothing) {
  Humanoid h = Humanoid::make();
  const std::size_t nb = h.scene.targets.bodies.size();
  std::vector<MeasuredPoint> pts;
  pts.reserve(128);
  BodyPoses poses;
  ChainResult r;
  const sim::SceneState st = h.state(1.0);
  h.frame(st, std::vector<int>(nb, -1), std::vector<bool>(nb, true), pts, poses);
  h.solver.solve(pts.data(), static_cast<int>(pts.size()), kHumanoidDt, poses, r);
  h.accept(poses, r, kHumanoidDt);
  std::vector<int> visible(nb, -1);
  std::vector<bool> found(nb, true);
  for (const char* b : {"forearm_l", "hand_l", "foot_r"}) {
    visible[static_cast<std::size_t>(h.body(b))] = 2;
    found[static_cast<std::size_t>(h.body(b))] = false;
  }
  h.frame(st, visible, found, pts, poses);
  test::AllocationScope scope;
  for (int i = 2; i < 30; ++i) {
    h.solver.solve(pts.data(), static_cast<int>(pts.size()), i * kHumanoidDt, poses, r);
    h.accept(poses, r, i * kHumanoidDt);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(r.joints[static_cast<std::size_t>(h.joint("wrist_l"))].solved_by,
            client::SolvedBy::kChain);
  EXPECT_GT(h.solver.counters().pose_refits, 0u);
}

TEST(PartialSigma, CentroidShiftOfACutDisc) {
  // Closed form against a numerically integrated disc cut by a straight edge.
  EXPECT_DOUBLE_EQ(partial_centroid_shift(1.0), 0.0);
  EXPECT_DOUBLE_EQ(partial_centroid_shift(0.0), 1.0);
  EXPECT_NEAR(partial_centroid_shift(0.5), 4.0 / (3.0 * std::numbers::pi), 1e-9);
  double last = 0.0;
  for (const double d : {0.9, 0.6, 0.3, 0.0, -0.3, -0.6, -0.9}) {
    constexpr int kN = 1000;  // samples per radius
    double area = 0.0, mx = 0.0;
    for (int i = -kN; i <= kN; ++i) {
      for (int k = -kN; k <= kN; ++k) {
        const double x = (i + 0.5) / kN, y = (k + 0.5) / kN;
        if (x * x + y * y > 1.0 || x > d) continue;
        area += 1.0;
        mx += x;
      }
    }
    const double f = area / (std::numbers::pi * kN * kN);
    const double shift = std::abs(mx / area);
    const double b = partial_centroid_shift(f);
    EXPECT_NEAR(b, shift, 2e-3) << "d = " << d;
    EXPECT_GT(b, last);  // more hidden, farther off
    last = b;
  }
  EXPECT_GT(partial_centroid_shift(1e-4), 0.95);  // a sliver: nearly the ball's radius
}

sim::SimOptions humanoid6_options() {
  sim::SimOptions so;
  so.scene = sim::SceneKind::kHumanoid;
  so.cameras = 6;
  so.frames = 12;
  so.seed = 5;
  return so;
}

TEST(HumanoidChain, SixCamerasCoverEveryObservableJoint) {
  // A short 6-camera recording of the humanoid with the true model: every joint valid
  // in the frames where it is observable (truth.h), none more than 2 deg off.
  const std::string& rec = test::simulated_recording("humanoid6", humanoid6_options());
  test::TempDir out("track_humanoid");
  OfflineTrackOptions o;
  o.recording_dir = rec;
  o.targets_path = rec + "/targets.yaml";
  o.model_path = rec + "/gt/model_true.yaml";
  o.out_dir = out.path();
  o.truth_dir = rec + "/gt";
  auto r = track_recording(o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->accuracy.has_value());
  ASSERT_EQ(r->accuracy->joints.size(), 14u);
  std::int64_t observable = 0, valid = 0;
  for (const JointAccuracy& j : r->accuracy->joints) {
    EXPECT_EQ(j.over_2deg, 0) << j.joint;
    EXPECT_GT(j.observable, 0) << j.joint;
    EXPECT_GE(j.valid_observable + 1, j.observable) << j.joint;  // at most one frame missed
    observable += j.observable;
    valid += j.valid_observable;
  }
  EXPECT_GE(static_cast<double>(valid), 0.98 * static_cast<double>(observable));
}

TEST(HumanoidChain, FrameProcessorWithTheModelAllocatesNothing) {
  // The whole per-frame path with the model: partial-point noise, chain solving, the
  // joint-centre refits and tests, the angles.
  const std::string& rec_dir = test::simulated_recording("humanoid6", humanoid6_options());
  auto rec = Recording::open(rec_dir);
  ASSERT_TRUE(rec.ok());
  auto targets = load_targets(rec_dir + "/targets.yaml");
  ASSERT_TRUE(targets.ok());
  auto model = load_model(rec_dir + "/gt/model_true.yaml", *targets);
  ASSERT_TRUE(model.ok());
  auto proc = FrameProcessor::create(rec->rig(), *targets, &*model, TrackerConfig{});
  ASSERT_TRUE(proc.ok()) << proc.error().message;
  const int cams = proc->camera_count();
  std::vector<std::vector<Image>> images;
  for (const FrameEntry& f : rec->frames()) {
    images.emplace_back(static_cast<std::size_t>(cams));
    for (int c = 0; c < cams; ++c) {
      auto r = rec->load_frame(c, f.frame, images.back()[static_cast<std::size_t>(c)]);
      ASSERT_TRUE(r.ok() && *r == FrameLoad::kOk);
    }
  }
  FrameOutput out = proc->make_output();
  std::vector<ImageView> views(static_cast<std::size_t>(cams));
  std::vector<const ImageView*> ptrs(static_cast<std::size_t>(cams));
  const auto run = [&](std::size_t i) {
    for (std::size_t c = 0; c < views.size(); ++c) {
      views[c] = images[i][c].view();
      ptrs[c] = &views[c];
    }
    proc->process(ptrs, rec->frames()[i].timestamp_ns, out);
  };
  for (std::size_t i = 0; i < 3; ++i) run(i);
  test::AllocationScope scope;
  for (std::size_t i = 3; i < images.size(); ++i) run(i);
  EXPECT_EQ(scope.count(), 0u);
  ASSERT_NE(proc->chain_counters(), nullptr);
  EXPECT_GT(proc->chain_counters()->pose_refits, 0u);  // the work was real
}

}  // namespace
}  // namespace mocap
