// Design: the simulator's built-in robots. Every scene is a kinematic tree of rigid
// bodies, each a set of capsules (limbs and the posts that hold the marker balls)
// carrying a marker target, joined by ball and hinge joints (SimJoint, in topological
// order from the root body), seen by built-in cameras or by a user-given rig of 2..32
// cameras (scene_rig.h). Two robots:
//  - the paper's shoulder test rig (build_shoulder_scene): three bodies (torso,
//    upper_arm, lower_arm), a ball joint (shoulder) and a hinge (elbow), seen by a
//    verged stereo pair like the paper's or by 3..8 cameras on an arc around it
//    (scene_cameras.h); two marker layouts (scene_layouts.h): `limbs` (default, markers
//    all around each limb on short bases) and `stalks` (the stress variant);
//  - a whole-body humanoid (scene_humanoid.h, `--scene humanoid`): 15 bodies, 14 joints,
//    71 markers, on a ring of 2..32 cameras around it.
// SimScene is immutable after build_scene(); a SceneState (body poses + noise key) is
// what changes per frame. apply_config() is the forward kinematics: allocation-free,
// noexcept. A JointConfig commands each joint in its own command axes (SimJoint::
// R_parent_cmd): a ball joint R_cmd = Rx(q0) Ry(q1) Rz(q2) about its centre, a hinge
// the angle q0 about its axis (right-hand rule), both relative to the reference pose.
// World frame: Z up, millimetres; body poses map body to world (X_world = T * X_body).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/scene_layouts.h"

namespace mocap::sim {

// The shoulder rig's bodies and joints (indices into its targets and its tree).
inline constexpr int kTorso = 0;
inline constexpr int kUpperArm = 1;
inline constexpr int kLowerArm = 2;
inline constexpr int kBodyCount = 3;
inline constexpr int kShoulderJoint = 0;
inline constexpr int kElbowJoint = 1;

// One joint of a scene's kinematic tree, in its parent's frame at the reference pose.
struct SimJoint {
  int parent = 0;  // body indices
  int child = 1;
  JointType type = JointType::kBall;
  Vec3 center_parent = Vec3::Zero();           // the joint centre (a point on a hinge axis)
  Vec3 axis_parent = Vec3::UnitX();            // hinge axis (unit)
  Mat3 R_parent_cmd = Mat3::Identity();        // the axes a ball joint's command is given in
  Iso3 T_parent_child_ref = Iso3::Identity();  // child pose at the reference configuration
  Vec3 lower_rad = Vec3::Zero();               // range of the commanded angles (motions)
  Vec3 upper_rad = Vec3::Zero();               // (a hinge uses x only)
};

// A capsule (segment a-b swept by a sphere), in its body's frame. Limbs and stalks are
// dark (they image at the background level) and occlude what lies behind them.
struct Capsule {
  int body = 0;
  Vec3 a_body = Vec3::Zero();
  Vec3 b_body = Vec3::Zero();
  double radius_mm = 1.0;
  bool shiny = false;  // a polished tube: source of the optional elongated reflection
};

// A small shiny spot on a limb (a screw head): the source of a specular glint.
struct GlintSpot {
  int body = 0;
  Vec3 point_body = Vec3::Zero();
  Vec3 normal_body = Vec3::UnitX();  // outward surface normal
  double peak_dn = 0.0;              // peak when the spot faces the camera
  // Irregular shape: up to three Gaussian lobes (dx_px, dy_px, sigma_px), amplitude 1, 0.7, 0.5.
  std::array<Vec3, 3> lobes{};
};

// The image formation parameters (every physical effect and its default; see
// docs/simulator.md). Levels are in DN of the output image.
struct ImagingParams {
  int bits = 8;                   // 8 or 16
  int maxval = 255;               // 255, or 4095 / 65535 for 16-bit output
  double background_dn = 12.0;    // ambient level of everything that is not a marker
  double marker_peak_dn = 175.0;  // marker disc centre brightness at reference_distance_mm
  double reference_distance_mm = 1000.0;
  double limb_factor = 0.7;           // I = peak * (a + (1 - a) cos(incidence)), a = limb_factor
  double read_noise_dn = 1.5;         // Gaussian read noise sigma
  double shot_gain_dn_per_e = 0.025;  // shot noise: variance_dn = gain * signal_dn
  double blur_sigma_px = 0.5;         // Gaussian optical PSF; 0 disables
  int supersample_edge = 8;           // samples per pixel side near a disc edge
  int supersample_interior = 4;       // samples per pixel side elsewhere on a disc
  double dropout_probability = 0.0;   // per marker, camera and frame
  bool streak = false;                // bright elongated reflection along the lower arm
  double streak_peak_dn = 200.0;
  double streak_sigma_px = 0.9;
  double glint_exponent = 4.0;  // glint brightness ~ cos(normal, view)^exponent
};

// Scales the 8-bit default levels to the output scale (bits, maxval).
ImagingParams default_imaging(int bits, int maxval);

struct SceneOptions {
  SceneKind kind = SceneKind::kLimbs;  // the robot and its marker layout
  std::optional<Rig> rig;              // user-given cameras (checked); none: the built-in ones
  int cameras =
      0;  // built-in cameras (2..8, humanoid 2..32; 0: the scene's default; ignored with a rig)
  std::string rig_source;  // names the user rig in errors (its file)
  std::uint64_t seed = 1;
  int stray_glints = 0;  // number of shiny spots on the limbs
  ImagingParams imaging{};
};

struct SimScene {
  SceneKind kind = SceneKind::kLimbs;
  Rig rig;
  TargetSet targets;                   // marker positions per body (body frames)
  JointModel joints_true;              // calibrated = true: the true model (gt/model_true.yaml)
  std::vector<Iso3> T_world_body_ref;  // the reference configuration (all angles 0)
  std::vector<Capsule> capsules;
  std::vector<GlintSpot> glints;
  ImagingParams imaging;
  double marker_radius_mm = 6.0;
  // Flattened marker list: body and index within the body's target.
  std::vector<int> marker_body;
  std::vector<int> marker_index;
  // The kinematic tree: joints in topological order (a parent's pose is known before its
  // children's), joint k is joints_true.joints[k]; root_body has no parent.
  std::vector<SimJoint> tree;
  int root_body = 0;
  // Where the whole-robot rigid motions (move400, viewpoints) rotate about (world).
  Vec3 robot_center_world = Vec3::Zero();

  int body_count() const noexcept { return static_cast<int>(targets.bodies.size()); }
  int joint_count() const noexcept { return static_cast<int>(tree.size()); }
  int marker_count() const noexcept { return static_cast<int>(marker_body.size()); }
  Vec3 marker_in_body(int m) const noexcept {
    return targets.bodies[static_cast<std::size_t>(marker_body[static_cast<std::size_t>(m)])]
        .markers_body[static_cast<std::size_t>(marker_index[static_cast<std::size_t>(m)])];
  }
};

// The commanded configuration of the robot: one command per joint of the scene's tree
// (make_config sizes it; apply_config ignores a config of another size).
struct JointConfig {
  Iso3 T_world_robot = Iso3::Identity();  // rigid motion of the whole robot (applied in world)
  std::vector<Vec3> q_rad;                // per joint: ball (q0, q1, q2), hinge (q0, -, -)
};

struct SceneState {
  std::vector<Iso3> T_world_body;  // sized body_count() at setup
  std::uint64_t noise_key = 0;     // per-frame key of every random decision
};

// The scene of options.kind: the shoulder rig (limbs, stalks) or the humanoid.
Expected<SimScene> build_scene(const SceneOptions& options);
Expected<SimScene> build_shoulder_scene(const SceneOptions& options);

// A state sized for the scene (setup; allocates).
SceneState make_state(const SimScene& scene);

// The reference configuration (every command 0), sized for the scene (setup; allocates).
JointConfig make_config(const SimScene& scene);

// Forward kinematics into a preallocated state (hot path).
void apply_config(const SimScene& scene, const JointConfig& config, SceneState& state) noexcept;

// The joint topology (joints.yaml): the true model without its parameters.
JointModel joint_topology(const SimScene& scene);

}  // namespace mocap::sim
