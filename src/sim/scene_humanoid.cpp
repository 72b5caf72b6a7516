// Design: see scene_humanoid.h. The numbers of the humanoid (docs/simulator.md has the
// tables): every limb is placed in the world at the reference pose (standing, arms
// hanging at the sides), then the marker layout is searched body by body under the
// target-design rules, and the joints are added in topological order from the pelvis.
#include "sim/scene_humanoid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/limb_layout.h"
#include "sim/scene_build.h"
#include "sim/scene_cameras.h"

namespace mocap::sim {
namespace {

constexpr double kPostRadiusMm = 2.0;  // the bases holding the balls
// The target-design rules (limb_layout.h); the seed is the robot's, not --seed's.
constexpr LayoutRules kRules{7.0, 40.0, 4.0, 5.5, 2.5, 2.0, 0x68756D616E6F6964ull};

struct JointDef {
  const char* name;
  JointType type;
  int parent, child;
  Vec3 center;
  Vec3 axis;    // hinges
  Vec3 lo_deg;  // range of the command
  Vec3 hi_deg;
};

std::vector<LimbBody> humanoid_bodies() {
  std::vector<LimbBody> b;
  // name, parent, limbs, markers, s range, azimuth range, frame rotation
  // The pelvis carries no ball underneath, between the legs.
  b.push_back(
      {"pelvis", -1, {{{-105, 0, 875}, {105, 0, 875}, 70}}, 5, 0.0, 1.0, -200, 20, {12, -6, 4}});
  b.push_back({"torso",
               0,
               {{{0, 0, 1060}, {0, 0, 1230}, 110}, {{-150, 0, 1290}, {150, 0, 1290}, 55}},
               6,
               0.12,
               0.88,
               -180,
               180,
               {-8, 5, -10}});
  b.push_back({"head",
               1,
               {{{0, -10, 1440}, {0, -10, 1530}, 82}, {{0, 0, 1335}, {0, 0, 1400}, 38}},
               4,
               0.0,
               1.0,
               -180,
               180,
               {15, 0, 7}});
  for (int side = 0; side < 2; ++side) {  // 0: left (+X), 1: right (-X)
    const double x = side == 0 ? 205.0 : -205.0;
    // Inner side (towards the body) is -X for the left limbs (phi -90), +X for the right.
    const double in = side == 0 ? -90.0 : 90.0;
    const int upper = static_cast<int>(b.size());
    const bool l = side == 0;
    b.push_back({l ? "upper_arm_l" : "upper_arm_r",
                 1,
                 {{{x, 0, 1265}, {x, 0, 1015}, 42}},
                 5,
                 0.18,
                 0.85,
                 in + 45,
                 in + 315,
                 {l ? 9.0 : -11.0, 6, -4}});
    b.push_back({l ? "forearm_l" : "forearm_r",
                 upper,
                 {{{x, 0, 985}, {x, 0, 770}, 36}},
                 5,
                 0.15,
                 0.9,
                 in + 45,
                 in + 315,
                 {l ? -13.0 : 10.0, -5, 8}});
    b.push_back({l ? "hand_l" : "hand_r",
                 upper + 1,
                 {{{x, -5, 715}, {x, -15, 615}, 32}},
                 4,
                 0.0,
                 1.0,
                 in + 45,
                 in + 315,
                 {l ? 7.0 : -6.0, 12, 5}});
  }
  for (int side = 0; side < 2; ++side) {
    const double x = side == 0 ? 100.0 : -100.0;
    const double in = side == 0 ? -90.0 : 90.0;
    const bool l = side == 0;
    const int thigh = static_cast<int>(b.size());
    b.push_back({l ? "thigh_l" : "thigh_r",
                 0,
                 {{{x, 0, 810}, {x, 0, 505}, 62}},
                 5,
                 0.05,
                 0.88,
                 in + 50,
                 in + 310,
                 {l ? -7.0 : 9.0, 4, 10}});
    b.push_back({l ? "shank_l" : "shank_r",
                 thigh,
                 {{{x, 0, 455}, {x, 0, 125}, 48}},
                 5,
                 0.1,
                 0.9,
                 in + 50,
                 in + 310,
                 {l ? 11.0 : -8.0, -7, 3}});
    b.push_back({l ? "foot_l" : "foot_r",
                 thigh + 1,
                 {{{x, 35, 48}, {x, -150, 40}, 38}},
                 4,
                 0.0,
                 1.0,
                 -100,
                 100,
                 {l ? -10.0 : 12.0, 6, -9}});
  }
  return b;
}

std::vector<JointDef> humanoid_joints() {
  const Vec3 z = Vec3::Zero();
  std::vector<JointDef> j;
  j.push_back({"waist", JointType::kBall, 0, 1, {0, 0, 950}, z, {-10, -15, -30}, {30, 15, 30}});
  j.push_back({"neck", JointType::kBall, 1, 2, {0, 0, 1365}, z, {-25, -20, -60}, {30, 20, 60}});
  for (int side = 0; side < 2; ++side) {
    const double x = side == 0 ? 205.0 : -205.0;
    const bool l = side == 0;
    const int upper = 3 + 3 * side;
    // Flexion forward is -x; abduction moves the arm away from the body (-y on the left).
    j.push_back({l ? "shoulder_l" : "shoulder_r",
                 JointType::kBall,
                 1,
                 upper,
                 {x, 0, 1290},
                 z,
                 {-95, l ? -60.0 : -5.0, -50},
                 {35, l ? 5.0 : 60.0, 50}});
    // +angle brings the hand forward (-Y).
    j.push_back({l ? "elbow_l" : "elbow_r",
                 JointType::kHinge,
                 upper,
                 upper + 1,
                 {x, 0, 1000},
                 {-1, 0, 0},
                 {5, 0, 0},
                 {135, 0, 0}});
    j.push_back({l ? "wrist_l" : "wrist_r",
                 JointType::kBall,
                 upper + 1,
                 upper + 2,
                 {x, 0, 745},
                 z,
                 {-50, -25, -60},
                 {50, 25, 60}});
  }
  for (int side = 0; side < 2; ++side) {
    const double x = side == 0 ? 100.0 : -100.0;
    const bool l = side == 0;
    const int thigh = 9 + 3 * side;
    j.push_back({l ? "hip_l" : "hip_r",
                 JointType::kBall,
                 0,
                 thigh,
                 {x, 0, 860},
                 z,
                 {-80, l ? -35.0 : -5.0, -35},
                 {20, l ? 5.0 : 35.0, 35}});
    // +angle swings the shank backwards (+Y); the ankle's +angle lowers the toes.
    j.push_back({l ? "knee_l" : "knee_r",
                 JointType::kHinge,
                 thigh,
                 thigh + 1,
                 {x, 0, 480},
                 {1, 0, 0},
                 {3, 0, 0},
                 {115, 0, 0}});
    j.push_back({l ? "ankle_l" : "ankle_r",
                 JointType::kHinge,
                 thigh + 1,
                 thigh + 2,
                 {x, 0, 85},
                 {1, 0, 0},
                 {-25, 0, 0},
                 {35, 0, 0}});
  }
  return j;
}

Mat3 frame_rotation(const Vec3& deg) {
  return rot_z(deg.x() * kRadPerDeg) * rot_x(deg.y() * kRadPerDeg) * rot_y(deg.z() * kRadPerDeg);
}

}  // namespace

std::vector<CameraModel> humanoid_cameras(const Vec3& center_world, int n) {
  std::vector<CameraModel> cams;
  if (n < kMinSimCameras || n > kMaxSimCameras) return cams;
  // 1280 x 1024 sensors behind ~6.7 mm lenses (fx ~1400 px at 4.8 um): the unit-to-unit
  // spread of the shoulder ring's lenses (built_in_cameras), re-centred.
  // A ring of more than 8 repeats the 8 lenses (camera k has lens k % 8).
  const std::vector<CameraModel> spread =
      built_in_cameras(SceneKind::kLimbs, Vec3::Zero(), kMaxArcCameras);
  for (int k = 0; k < n; ++k) {
    const double az_deg = n == 2 ? (k == 0 ? -25.0 : 25.0) : 22.5 + 360.0 * k / n;
    const double z = n == 2 ? 1900.0 : (k % 2 == 0 ? 2300.0 : 1500.0);
    const double a = az_deg * kRadPerDeg;
    const Vec3 centre(center_world.x() + 3000.0 * std::sin(a),
                      center_world.y() - 3000.0 * std::cos(a), z);
    const CameraModel& lens = spread[static_cast<std::size_t>(k % kMaxArcCameras)];
    CameraModel cam;
    cam.name = "cam" + std::to_string(k);
    cam.width = 1280;
    cam.height = 1024;
    cam.fx = 1400.0 + (lens.fx - 1290.0);
    cam.fy = 1400.0 + (lens.fy - 1290.0);
    cam.cx = 639.5 + (lens.cx - 515.5);
    cam.cy = 511.5 + (lens.cy - 387.5);
    cam.distortion = lens.distortion;
    for (int i = 0; i < 2; ++i) cam.distortion[static_cast<std::size_t>(i)] *= 0.75;
    // Aimed at the centre, image x horizontal, the same small roll as the lens slot.
    const Vec3 zc = (center_world - centre).normalized();
    const Vec3 xc = zc.cross(Vec3::UnitZ()).normalized();
    const Vec3 yc = zc.cross(xc);
    Mat3 R;
    R.row(0) = xc.transpose();
    R.row(1) = yc.transpose();
    R.row(2) = zc.transpose();
    // The slot's roll, recovered from its look-at construction (its x axis vs horizontal).
    const Vec3 lx = lens.R_cam_world.row(0).transpose();
    const Vec3 lz = lens.R_cam_world.row(2).transpose();
    const Vec3 lx0 = lz.cross(Vec3::UnitZ()).normalized();
    const double roll = std::atan2(-lx0.cross(lx).dot(lz), lx0.dot(lx));
    cam.R_cam_world = rot_z(roll) * R;
    cam.t_cam_world = -cam.R_cam_world * centre;
    cams.push_back(cam);
  }
  return cams;
}

Expected<SimScene> build_humanoid_scene(const SceneOptions& options) {
  if (auto r = check_scene_options(options); !r) return r.error();
  const int cameras = options.cameras == 0 ? kHumanoidDefaultCameras : options.cameras;
  SimScene scene;
  scene.kind = SceneKind::kHumanoid;
  scene.imaging = options.imaging;
  // The lab sets strobe and exposure for its volume: the default peak at 3 m.
  scene.imaging.reference_distance_mm = 3000.0;
  scene.marker_radius_mm = kRules.ball_radius_mm;
  scene.targets.marker_diameter_mm = 2.0 * kRules.ball_radius_mm;
  scene.robot_center_world = Vec3(0.0, 0.0, 850.0);
  scene.root_body = 0;

  const std::vector<LimbBody> bodies = humanoid_bodies();
  for (const LimbBody& b : bodies) {
    const LimbCapsule& main = b.limbs[0];
    scene.T_world_body_ref.push_back(
        make_iso(frame_rotation(b.frame_rot_deg), 0.5 * (main.a + main.b)));
    MarkerTarget t;
    t.name = b.name;
    scene.targets.bodies.push_back(std::move(t));
  }
  // The layout is the robot's: searched once per process.
  static const Expected<std::vector<std::vector<Mount>>> layout =
      search_limb_layout(bodies, kRules);
  if (!layout) return layout.error();
  for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
    const int b = static_cast<int>(bi);
    // The forearms are polished tubes (the source of --streak's reflection).
    const bool shiny = std::string(bodies[bi].name).rfind("forearm", 0) == 0;
    for (const LimbCapsule& l : bodies[bi].limbs)
      add_capsule(scene, b, l.a, l.b, l.radius_mm, shiny);
    for (const Mount& m : (*layout)[bi]) add_marker(scene, b, m.center, m.post_root, kPostRadiusMm);
  }
  for (const JointDef& j : humanoid_joints()) {
    // Ball joints are commanded in world-aligned axes at the reference pose.
    const Mat3 R_parent_cmd =
        scene.T_world_body_ref[static_cast<std::size_t>(j.parent)].linear().transpose();
    const Vec3 axis = j.type == JointType::kHinge ? j.axis.normalized() : Vec3::UnitX();
    add_joint(scene, j.name, j.type, j.parent, j.child, j.center, axis, R_parent_cmd,
              j.lo_deg * kRadPerDeg, j.hi_deg * kRadPerDeg);
  }
  if (auto r =
          set_cameras(options, humanoid_cameras(scene.robot_center_world, cameras), true, scene);
      !r)
    return r.error();
  place_glints(options, scene);
  return scene;
}

}  // namespace mocap::sim
