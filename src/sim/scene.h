// Design: the simulator's built-in scenario, the paper's shoulder test rig: three
// rigid bodies (torso, upper_arm, lower_arm), each a set of capsules (limbs and the
// posts that hold the 12 mm marker balls) carrying a marker target, a ball joint
// (shoulder: torso -> upper_arm) and a hinge (elbow: upper_arm -> lower_arm), seen by a
// verged stereo pair like the paper's, by 3..8 built-in cameras on an arc around the
// robot (scene_cameras.h), or by a user-given rig of 2..8 cameras (scene_rig.h). Two marker
// layouts (scene_layouts.h): `limbs` (default, markers all around each limb on short
// bases) and `stalks` (the stress variant). SimScene is immutable after
// build_shoulder_scene(); a SceneState (body poses + noise key) is what changes per
// frame. apply_config() is the forward kinematics: allocation-free, noexcept.
// World frame: X to the right as seen from the cameras, Y away from the cameras
// (depth), Z up; millimetres. Body poses map body to world (X_world = T * X_body).
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

inline constexpr int kTorso = 0;
inline constexpr int kUpperArm = 1;
inline constexpr int kLowerArm = 2;
inline constexpr int kBodyCount = 3;

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
  SceneKind kind = SceneKind::kLimbs;  // marker layout
  std::optional<Rig> rig;              // user-given cameras (checked); none: the built-in ones
  int cameras = 2;                     // built-in cameras (2..8; ignored with a rig)
  std::string rig_source;              // names the user rig in errors (its file)
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
  // Kinematic reference (parent-frame quantities at the reference configuration).
  Vec3 shoulder_center_torso = Vec3::Zero();
  Vec3 elbow_center_upper = Vec3::Zero();
  Vec3 elbow_axis_upper = Vec3::UnitX();
  Iso3 T_torso_upper_ref = Iso3::Identity();
  Iso3 T_upper_lower_ref = Iso3::Identity();
  // Where the whole-robot rigid motions (move400, viewpoints) rotate about (world).
  Vec3 robot_center_world = Vec3::Zero();

  int marker_count() const noexcept { return static_cast<int>(marker_body.size()); }
  Vec3 marker_in_body(int m) const noexcept {
    return targets.bodies[static_cast<std::size_t>(marker_body[static_cast<std::size_t>(m)])]
        .markers_body[static_cast<std::size_t>(marker_index[static_cast<std::size_t>(m)])];
  }
};

// The commanded configuration of the robot.
struct JointConfig {
  Iso3 T_world_robot = Iso3::Identity();  // rigid motion of the whole robot (applied in world)
  Vec3 shoulder_rad = Vec3::Zero();       // R_cmd = Rx(q0) Ry(q1) Rz(q2) in torso axes
  double elbow_rad = 0.0;                 // about the elbow axis, right-hand rule
};

struct SceneState {
  std::vector<Iso3> T_world_body;  // sized kBodyCount at setup
  std::uint64_t noise_key = 0;     // per-frame key of every random decision
};

Expected<SimScene> build_shoulder_scene(const SceneOptions& options);

// A state sized for the scene (setup; allocates).
SceneState make_state(const SimScene& scene);

// Forward kinematics into a preallocated state (hot path).
void apply_config(const SimScene& scene, const JointConfig& config, SceneState& state) noexcept;

// The joint topology (joints.yaml): the true model without its parameters.
JointModel joint_topology(const SimScene& scene);

}  // namespace mocap::sim
