// Design: the numbers of the built-in shoulder test rig (documented, with a drawing
// of the layout, in docs/simulator.md), the scene helpers of scene_build.h and the
// generic forward kinematics. Everything is first placed in the world at the
// reference configuration (arm hanging straight down) and then expressed in each
// body's own frame, so the body frames are deliberately not aligned with the world or
// with each other (a tracker must not rely on such coincidences).
#include "sim/scene.h"

#include <cmath>
#include <numbers>
#include <string>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/scene_build.h"
#include "sim/scene_cameras.h"
#include "sim/scene_humanoid.h"
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

Expected<void> check_scene_options(const SceneOptions& options) {
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
  // Built-in cameras: the humanoid's ring takes up to kMaxSimCameras, the arc up to 8.
  const int max_built_in = options.kind == SceneKind::kHumanoid ? kMaxSimCameras : kMaxArcCameras;
  if (!options.rig && options.cameras != 0 &&
      (options.cameras < kMinSimCameras || options.cameras > max_built_in)) {
    return make_error("simulate", "cameras",
                      "must be " + std::to_string(kMinSimCameras) + ".." +
                          std::to_string(max_built_in) + " for this scene, got " +
                          std::to_string(options.cameras));
  }
  return {};
}

void add_capsule(SimScene& scene, int body, const Vec3& a_world, const Vec3& b_world,
                 double radius_mm, bool shiny) {
  const Iso3 T_body_world = scene.T_world_body_ref[static_cast<std::size_t>(body)].inverse();
  scene.capsules.push_back(
      Capsule{body, T_body_world * a_world, T_body_world * b_world, radius_mm, shiny});
}

int add_marker(SimScene& scene, int body, const Vec3& center_world, const Vec3& post_root_world,
               double post_radius_mm) {
  const auto ub = static_cast<std::size_t>(body);
  const Iso3 T_body_world = scene.T_world_body_ref[ub].inverse();
  scene.capsules.push_back(Capsule{body, T_body_world * post_root_world,
                                   T_body_world * center_world, post_radius_mm, false});
  MarkerTarget& target = scene.targets.bodies[ub];
  const int index = static_cast<int>(target.markers_body.size());
  scene.marker_body.push_back(body);
  scene.marker_index.push_back(index);
  target.markers_body.push_back(T_body_world * center_world);
  return index;
}

void add_joint(SimScene& scene, const std::string& name, JointType type, int parent, int child,
               const Vec3& center_world, const Vec3& axis_world, const Mat3& R_parent_cmd,
               const Vec3& lower_rad, const Vec3& upper_rad) {
  const Iso3& T_wp = scene.T_world_body_ref[static_cast<std::size_t>(parent)];
  const Iso3& T_wc = scene.T_world_body_ref[static_cast<std::size_t>(child)];
  SimJoint sj;
  sj.parent = parent;
  sj.child = child;
  sj.type = type;
  sj.center_parent = T_wp.inverse() * center_world;
  sj.axis_parent = T_wp.linear().transpose() * axis_world;
  sj.R_parent_cmd = R_parent_cmd;
  sj.T_parent_child_ref = T_wp.inverse() * T_wc;
  sj.lower_rad = lower_rad;
  sj.upper_rad = upper_rad;
  scene.tree.push_back(sj);

  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = scene.targets.bodies[static_cast<std::size_t>(parent)].name;
  j.child = scene.targets.bodies[static_cast<std::size_t>(child)].name;
  j.parent_index = parent;
  j.child_index = child;
  j.calibrated = true;
  j.center_parent = sj.center_parent;
  j.center_child = T_wc.inverse() * center_world;
  if (type == JointType::kHinge) {
    j.axis_parent = sj.axis_parent;
    j.axis_child = T_wc.linear().transpose() * axis_world;
    // The hinge's zero: R_parent^T R_child at the reference configuration.
    const Quat q0 = canonical_quat(sj.T_parent_child_ref.linear());
    j.extra.emplace_back("zero_q_parent_child",
                         std::vector<double>{q0.w(), q0.x(), q0.y(), q0.z()});
  }
  scene.joints_true.joints.push_back(std::move(j));
}

void limb_azimuth_frame(const Vec3& a, const Vec3& b, Vec3& d, Vec3& front, Vec3& side) {
  d = (b - a).normalized();
  const Vec3 up = d.z() < 0.0 ? Vec3(-d) : d;
  front = Vec3(0.0, -1.0, 0.0) - up.dot(Vec3(0.0, -1.0, 0.0)) * up;
  if (front.norm() < 0.3) front = Vec3::UnitZ() - up.z() * up;
  front.normalize();
  side = -front.cross(up);
}

void place_glints(const SceneOptions& options, SimScene& scene) {
  Rng rng(hash_mix(options.seed, 0x6C696E74ull));
  const double scale = static_cast<double>(scene.imaging.maxval) / 255.0;
  const int bodies = scene.body_count();
  for (int g = 0; g < options.stray_glints; ++g) {
    const int b = g % bodies;
    const Iso3& T_wb = scene.T_world_body_ref[static_cast<std::size_t>(b)];
    const Capsule* limb = nullptr;
    for (const Capsule& c : scene.capsules) {
      if (c.body == b) {
        limb = &c;
        break;
      }
    }
    const double s = rng.uniform(0.15, 0.85);
    const double phi_deg = rng.uniform(-100.0, 100.0);
    GlintSpot spot;
    spot.body = b;
    spot.peak_dn = rng.uniform(150.0, 255.0) * scale;
    for (auto& lobe : spot.lobes) {
      lobe = Vec3(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(0.5, 1.3));
    }
    spot.lobes[0].head<2>().setZero();
    if (limb == nullptr) continue;
    const Vec3 a = T_wb * limb->a_body, e = T_wb * limb->b_body;
    // The azimuth about the limb axis; for a vertical limb that is radial_dir(phi).
    Vec3 d, front, side;
    limb_azimuth_frame(a, e, d, front, side);
    const Vec3 dir = std::sin(phi_deg * kRadPerDeg) * side + std::cos(phi_deg * kRadPerDeg) * front;
    const Vec3 axis_pt = a + s * (e - a);
    const Iso3 T_body_world = T_wb.inverse();
    spot.point_body = T_body_world * (axis_pt + dir * limb->radius_mm);
    spot.normal_body = T_body_world.linear() * dir;
    scene.glints.push_back(spot);
  }
}

Expected<void> set_cameras(const SceneOptions& options, std::vector<CameraModel> built_in,
                           bool check_built_in, SimScene& scene) {
  if (options.rig) {  // a user-given rig replaces the built-in cameras
    const std::string source = options.rig_source.empty() ? "rig" : options.rig_source;
    if (auto r = check_rig_for_scene(*options.rig, scene, source); !r) return r.error();
    scene.rig = *options.rig;
    return {};
  }
  scene.rig.cameras = std::move(built_in);
  if (check_built_in) {
    const std::string source =
        "simulate: built-in " + std::to_string(scene.rig.cameras.size()) + "-camera rig";
    if (auto r = check_rig_for_scene(scene.rig, scene, source); !r) return r.error();
  }
  return {};
}

Expected<SimScene> build_scene(const SceneOptions& options) {
  if (options.kind == SceneKind::kHumanoid) return build_humanoid_scene(options);
  return build_shoulder_scene(options);
}

Expected<SimScene> build_shoulder_scene(const SceneOptions& options) {
  if (auto r = check_scene_options(options); !r) return r.error();
  const int cameras = options.cameras == 0 ? 2 : options.cameras;

  SimScene scene;
  scene.imaging = options.imaging;
  scene.marker_radius_mm = 6.0;
  scene.kind = options.kind;

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
    MarkerTarget target;
    target.name = names[ub];
    scene.targets.bodies.push_back(std::move(target));
    for (const Limb& limb : limbs[ub])
      add_capsule(scene, b, limb.a_world, limb.b_world, limb.radius_mm, b == kLowerArm);
    const Limb& main = limbs[ub][0];
    for (const MarkerMount& p : layout.mounts[ub]) {
      const Vec3 axis_pt(main.a_world.x(), main.a_world.y(), p.z_mm);
      const Vec3 dir = radial_dir(p.phi_deg);
      const Vec3 center = axis_pt + dir * (main.radius_mm + p.gap_mm + scene.marker_radius_mm);
      const Vec3 post_root = axis_pt + dir * (main.radius_mm - 3.0);
      add_marker(scene, b, center, post_root, layout.post_radius_mm);
    }
  }

  // The true joint model: the shoulder commanded in torso axes, the elbow about its axis.
  const double d = kRadPerDeg;
  add_joint(scene, "shoulder", JointType::kBall, kTorso, kUpperArm, shoulder_world, Vec3::UnitX(),
            Mat3::Identity(), Vec3(-70.0, -58.0, -40.0) * d, Vec3(15.0, 2.0, 40.0) * d);
  add_joint(scene, "elbow", JointType::kHinge, kUpperArm, kLowerArm, elbow_world, elbow_axis_world,
            Mat3::Identity(), Vec3(8.0, 0.0, 0.0) * d, Vec3(113.0, 0.0, 0.0) * d);

  // The ring goes through the user rig's scene check; the pair is the paper's.
  if (auto r =
          set_cameras(options, built_in_cameras(options.kind, scene.robot_center_world, cameras),
                      cameras > 2, scene);
      !r)
    return r.error();
  place_glints(options, scene);
  return scene;
}

SceneState make_state(const SimScene& scene) {
  SceneState s;
  s.T_world_body = scene.T_world_body_ref;
  return s;
}

JointConfig make_config(const SimScene& scene) {
  JointConfig c;
  c.q_rad.assign(scene.tree.size(), Vec3::Zero());
  return c;
}

void apply_config(const SimScene& scene, const JointConfig& config, SceneState& state) noexcept {
  if (state.T_world_body.size() != scene.T_world_body_ref.size() ||
      config.q_rad.size() != scene.tree.size())
    return;
  const auto root = static_cast<std::size_t>(scene.root_body);
  state.T_world_body[root] = config.T_world_robot * scene.T_world_body_ref[root];
  for (std::size_t k = 0; k < scene.tree.size(); ++k) {
    const SimJoint& j = scene.tree[k];
    const Vec3& q = config.q_rad[k];
    Iso3 motion = Iso3::Identity();
    if (j.type == JointType::kBall) {
      motion.linear() = j.R_parent_cmd * euler_xyz_to_rotation(q) * j.R_parent_cmd.transpose();
    } else {
      motion.linear() = Eigen::AngleAxisd(q.x(), j.axis_parent).toRotationMatrix();
    }
    motion.translation() = j.center_parent - motion.linear() * j.center_parent;
    state.T_world_body[static_cast<std::size_t>(j.child)] =
        state.T_world_body[static_cast<std::size_t>(j.parent)] * motion * j.T_parent_child_ref;
  }
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
