// Design: the numbers of the built-in shoulder test rig (documented, with a drawing
// of the layout, in docs/simulator.md). Everything is first placed in the world at the
// reference configuration (arm hanging straight down) and then expressed in each
// body's own frame, so the body frames are deliberately not aligned with the world or
// with each other (a tracker must not rely on such coincidences).
#include "sim/scene.h"

#include <cmath>
#include <numbers>
#include <string>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/scene_cameras.h"
#include "sim/scene_rig.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

struct Limb {
  Vec3 a_world, b_world;
  double radius_mm;
};

Vec3 radial_dir(double phi_deg) {
  return Vec3(std::sin(phi_deg * kRadPerDeg), -std::cos(phi_deg * kRadPerDeg), 0.0);
}

}  // namespace

ImagingParams default_imaging(int bits, int maxval) {
  ImagingParams p;
  p.bits = bits;
  p.maxval = maxval;
  const double s = static_cast<double>(maxval) / 255.0;
  p.background_dn *= s;
  p.marker_peak_dn *= s;
  p.read_noise_dn *= s;
  p.shot_gain_dn_per_e *= s;  // variance scales with s^2: gain * signal, both scaled by s
  p.streak_peak_dn *= s;
  return p;
}

Expected<SimScene> build_shoulder_scene(const SceneOptions& options) {
  const ImagingParams& im = options.imaging;
  if (im.bits != 8 && im.bits != 16) return make_error("simulate", "bits", "must be 8 or 16");
  if (im.maxval < 1 || im.maxval > (im.bits == 8 ? 255 : 65535) ||
      (im.bits == 16 && im.maxval < 256))
    return make_error("simulate", "maxval", "out of range for the bit depth");
  if (im.supersample_edge < 1 || im.supersample_edge > 32 || im.supersample_interior < 1 ||
      im.supersample_interior > 32)
    return make_error("simulate", "supersample", "must be 1..32");
  if (!(im.blur_sigma_px >= 0.0 && im.blur_sigma_px <= 5.0))
    return make_error("simulate", "blur", "sigma must be in [0, 5] px");
  if (!(im.read_noise_dn >= 0.0) || !(im.shot_gain_dn_per_e >= 0.0))
    return make_error("simulate", "noise", "must be >= 0");
  if (!(im.dropout_probability >= 0.0 && im.dropout_probability <= 1.0))
    return make_error("simulate", "dropout", "probability must be in [0, 1]");
  if (options.stray_glints < 0 || options.stray_glints > 64)
    return make_error("simulate", "stray", "must be 0..64");

  SimScene scene;
  scene.imaging = im;
  scene.marker_radius_mm = 6.0;
  scene.kind = options.kind;
  if (!options.rig && (options.cameras < kMinSimCameras || options.cameras > kMaxSimCameras)) {
    return make_error("simulate", "cameras",
                      "must be " + std::to_string(kMinSimCameras) + ".." +
                          std::to_string(kMaxSimCameras) + ", got " +
                          std::to_string(options.cameras));
  }

  // Body frames at the reference configuration (deliberately rotated).
  scene.T_world_body_ref = {
      make_iso(rot_z(10.0 * kRadPerDeg), Vec3(-170.0, 60.0, 40.0)),
      make_iso(rot_z(-15.0 * kRadPerDeg) * rot_x(5.0 * kRadPerDeg), Vec3(-60.0, 40.0, 50.0)),
      make_iso(rot_y(20.0 * kRadPerDeg) * rot_z(30.0 * kRadPerDeg), Vec3(-60.0, 40.0, -140.0))};
  const Vec3 shoulder_world(-60.0, 40.0, 150.0);
  const Vec3 elbow_world(-60.0, 40.0, -50.0);
  const Vec3 elbow_axis_world(-1.0, 0.0,
                              0.0);  // positive angle bends the forearm towards the cameras
  scene.robot_center_world = Vec3(-90.0, 45.0, 20.0);

  // Limbs (world, reference configuration) per body.
  const std::array<std::vector<Limb>, kBodyCount> limbs = {{
      {{Vec3(-170.0, 60.0, -120.0), Vec3(-170.0, 60.0, 200.0), 55.0},
       {Vec3(-170.0, 60.0, 150.0), Vec3(-92.0, 42.0, 150.0), 26.0}},
      {{shoulder_world, elbow_world, 35.0}},
      {{elbow_world, Vec3(-60.0, 40.0, -235.0), 28.0}},
  }};
  // Marker mounts on each body's main limb (scene_layouts.cpp).
  const MarkerLayout& layout = marker_layout(options.kind);
  const std::array<const char*, kBodyCount> names = {"torso", "upper_arm", "lower_arm"};

  scene.targets.marker_diameter_mm = 2.0 * scene.marker_radius_mm;
  for (int b = 0; b < kBodyCount; ++b) {
    const auto ub = static_cast<std::size_t>(b);
    const Iso3 T_body_world = scene.T_world_body_ref[ub].inverse();
    MarkerTarget target;
    target.name = names[ub];
    for (const Limb& limb : limbs[ub]) {
      scene.capsules.push_back(Capsule{b, T_body_world * limb.a_world, T_body_world * limb.b_world,
                                       limb.radius_mm, b == kLowerArm});
    }
    const Limb& main = limbs[ub][0];
    for (const MarkerMount& p : layout.mounts[ub]) {
      const Vec3 axis_pt(main.a_world.x(), main.a_world.y(), p.z_mm);
      const Vec3 dir = radial_dir(p.phi_deg);
      const Vec3 center = axis_pt + dir * (main.radius_mm + p.gap_mm + scene.marker_radius_mm);
      const Vec3 post_root = axis_pt + dir * (main.radius_mm - 3.0);
      scene.capsules.push_back(Capsule{b, T_body_world * post_root, T_body_world * center,
                                       layout.post_radius_mm, false});
      scene.marker_body.push_back(b);
      scene.marker_index.push_back(static_cast<int>(target.markers_body.size()));
      target.markers_body.push_back(T_body_world * center);
    }
    scene.targets.bodies.push_back(std::move(target));
  }

  // The true joint model.
  const Iso3& T_wt = scene.T_world_body_ref[kTorso];
  const Iso3& T_wu = scene.T_world_body_ref[kUpperArm];
  const Iso3& T_wl = scene.T_world_body_ref[kLowerArm];
  scene.shoulder_center_torso = T_wt.inverse() * shoulder_world;
  scene.elbow_center_upper = T_wu.inverse() * elbow_world;
  scene.elbow_axis_upper = T_wu.linear().transpose() * elbow_axis_world;
  scene.T_torso_upper_ref = T_wt.inverse() * T_wu;
  scene.T_upper_lower_ref = T_wu.inverse() * T_wl;

  JointSpec shoulder;
  shoulder.name = "shoulder";
  shoulder.type = JointType::kBall;
  shoulder.parent = "torso";
  shoulder.child = "upper_arm";
  shoulder.parent_index = kTorso;
  shoulder.child_index = kUpperArm;
  shoulder.calibrated = true;
  shoulder.center_parent = scene.shoulder_center_torso;
  shoulder.center_child = T_wu.inverse() * shoulder_world;
  JointSpec elbow;
  elbow.name = "elbow";
  elbow.type = JointType::kHinge;
  elbow.parent = "upper_arm";
  elbow.child = "lower_arm";
  elbow.parent_index = kUpperArm;
  elbow.child_index = kLowerArm;
  elbow.calibrated = true;
  elbow.center_parent = scene.elbow_center_upper;
  elbow.center_child = T_wl.inverse() * elbow_world;
  elbow.axis_parent = scene.elbow_axis_upper;
  elbow.axis_child = T_wl.linear().transpose() * elbow_axis_world;
  // The hinge's zero: R_parent^T R_child at the reference configuration.
  const Quat q0 = canonical_quat(scene.T_upper_lower_ref.linear());
  elbow.extra.emplace_back("zero_q_parent_child",
                           std::vector<double>{q0.w(), q0.x(), q0.y(), q0.z()});
  scene.joints_true.joints = {shoulder, elbow};

  if (options.rig) {  // a user-given rig replaces the built-in cameras
    const std::string source = options.rig_source.empty() ? "rig" : options.rig_source;
    if (auto r = check_rig_for_scene(*options.rig, scene, source); !r) return r.error();
    scene.rig = *options.rig;
  } else {
    scene.rig.cameras = built_in_cameras(options.kind, scene.robot_center_world, options.cameras);
    if (options.cameras > 2) {  // the ring goes through the user rig's scene check
      const std::string source =
          "simulate: built-in " + std::to_string(options.cameras) + "-camera rig";
      if (auto r = check_rig_for_scene(scene.rig, scene, source); !r) return r.error();
    }
  }

  // Shiny spots (glints) on the limbs, placed from the seed.
  Rng rng(hash_mix(options.seed, 0x6C696E74ull));
  const double scale = static_cast<double>(im.maxval) / 255.0;
  for (int g = 0; g < options.stray_glints; ++g) {
    const int b = g % kBodyCount;
    const Limb& limb = limbs[static_cast<std::size_t>(b)][0];
    const double s = rng.uniform(0.15, 0.85);
    const Vec3 axis_pt = limb.a_world + s * (limb.b_world - limb.a_world);
    const Vec3 dir = radial_dir(rng.uniform(-100.0, 100.0));
    const Iso3 T_body_world = scene.T_world_body_ref[static_cast<std::size_t>(b)].inverse();
    GlintSpot spot;
    spot.body = b;
    spot.point_body = T_body_world * (axis_pt + dir * limb.radius_mm);
    spot.normal_body = T_body_world.linear() * dir;
    spot.peak_dn = rng.uniform(150.0, 255.0) * scale;
    for (auto& lobe : spot.lobes) {
      lobe = Vec3(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(0.5, 1.3));
    }
    spot.lobes[0].head<2>().setZero();
    scene.glints.push_back(spot);
  }
  return scene;
}

SceneState make_state(const SimScene& scene) {
  SceneState s;
  s.T_world_body = scene.T_world_body_ref;
  return s;
}

void apply_config(const SimScene& scene, const JointConfig& config, SceneState& state) noexcept {
  if (state.T_world_body.size() != static_cast<std::size_t>(kBodyCount)) return;
  const Iso3 T_world_torso = config.T_world_robot * scene.T_world_body_ref[kTorso];
  const Vec3& c_t = scene.shoulder_center_torso;
  Iso3 shoulder = Iso3::Identity();
  shoulder.linear() = euler_xyz_to_rotation(config.shoulder_rad);
  shoulder.translation() = c_t - shoulder.linear() * c_t;
  const Iso3 T_world_upper = T_world_torso * shoulder * scene.T_torso_upper_ref;
  const Vec3& c_u = scene.elbow_center_upper;
  Iso3 elbow = Iso3::Identity();
  elbow.linear() = Eigen::AngleAxisd(config.elbow_rad, scene.elbow_axis_upper).toRotationMatrix();
  elbow.translation() = c_u - elbow.linear() * c_u;
  state.T_world_body[kTorso] = T_world_torso;
  state.T_world_body[kUpperArm] = T_world_upper;
  state.T_world_body[kLowerArm] = T_world_upper * elbow * scene.T_upper_lower_ref;
}

JointModel joint_topology(const SimScene& scene) {
  JointModel m = scene.joints_true;
  for (auto& j : m.joints) {
    j.calibrated = false;
    j.extra.clear();
  }
  return m;
}

}  // namespace mocap::sim
