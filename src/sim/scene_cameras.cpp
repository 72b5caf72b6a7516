// Design: see scene_cameras.h. Both placements use the same look-at construction: the
// optical axis from the camera centre to its aim point, image x horizontal (axis x
// world Z), image y down, then a small mounting roll about the optical axis. The pair
// is built exactly as before the ring existed (same arithmetic, same numbers).
#include "sim/scene_cameras.h"

#include <array>
#include <cmath>
#include <string>

#include "core/rotation.h"
#include "core/units.h"

namespace mocap::sim {
namespace {

// One camera's lens and mount roll: the scene's 6 mm optics with unit-to-unit spread.
struct Lens {
  double fx, fy, cx, cy;
  std::array<double, 5> distortion;
  double roll_deg;
};

// Slots 0 and 1 are the pair's lenses; the others spread like the pair's two units do.
constexpr std::array<Lens, kMaxArcCameras> kRingLenses = {{
    {1291.2, 1290.6, 517.3, 385.9, {-0.121, 0.083, 0.0004, -0.0003, 0.0}, 0.3},
    {1288.7, 1288.1, 513.8, 389.4, {-0.118, 0.079, -0.0002, 0.0005, 0.0}, -0.4},
    {1293.4, 1292.9, 519.6, 384.2, {-0.124, 0.087, 0.0003, 0.0002, 0.0}, 0.5},
    {1287.1, 1286.8, 512.2, 390.8, {-0.116, 0.076, -0.0004, -0.0001, 0.0}, -0.2},
    {1290.0, 1289.2, 516.1, 391.3, {-0.120, 0.081, 0.0001, 0.0004, 0.0}, 0.2},
    {1294.8, 1294.1, 511.4, 386.5, {-0.123, 0.085, -0.0003, 0.0003, 0.0}, -0.5},
    {1286.3, 1285.9, 520.2, 383.7, {-0.117, 0.078, 0.0002, -0.0004, 0.0}, 0.4},
    {1292.2, 1291.4, 514.7, 388.6, {-0.122, 0.084, -0.0001, 0.0001, 0.0}, -0.3},
}};

// The arc: first and last azimuth, horizontal distance, the two heights.
constexpr double kArcFirstDeg = -60.0;
constexpr double kArcLastDeg = 150.0;
constexpr double kRingDistanceMm = 1500.0;
constexpr double kRingHighMm = 900.0;
constexpr double kRingLowMm = 450.0;

CameraModel look_at(const std::string& name, const Lens& lens, const Vec3& center,
                    const Vec3& aim) {
  CameraModel cam;
  cam.name = name;
  cam.width = 1032;
  cam.height = 776;
  cam.fx = lens.fx;
  cam.fy = lens.fy;
  cam.cx = lens.cx;
  cam.cy = lens.cy;
  cam.distortion = lens.distortion;
  const Vec3 z = (aim - center).normalized();
  const Vec3 x = z.cross(Vec3::UnitZ()).normalized();
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  R = rot_z(lens.roll_deg * kRadPerDeg) * R;  // a small mounting roll about the optical axis
  cam.R_cam_world = R;
  cam.t_cam_world = -R * center;
  return cam;
}

}  // namespace

RingSlot ring_slot(int k, int n) noexcept {
  RingSlot s;
  const double step = n > 1 ? (kArcLastDeg - kArcFirstDeg) / (n - 1) : 0.0;
  s.azimuth_deg = kArcFirstDeg + step * k;
  s.distance_mm = kRingDistanceMm;
  s.height_mm = k % 2 == 0 ? kRingHighMm : kRingLowMm;
  return s;
}

std::vector<CameraModel> built_in_cameras(SceneKind kind, const Vec3& robot_center_world, int n) {
  std::vector<CameraModel> cams;
  if (n < kMinSimCameras || n > kMaxArcCameras) return cams;
  if (n == 2) {  // the verged pair: x = mount.x -+ 238.5, aimed at (mount.x, 250, aim_z)
    const CameraMount mount = camera_mount(kind);
    const Vec3 aim(mount.x_mm, 250.0, mount.aim_z_mm);  // where the optical axes cross
    for (int k = 0; k < 2; ++k) {
      const double dx = k == 0 ? -238.5 : 238.5;
      const Vec3 center(mount.x_mm + dx, mount.y_mm, mount.z_mm);
      cams.push_back(look_at("cam" + std::to_string(k), kRingLenses[static_cast<std::size_t>(k)],
                             center, aim));
    }
    return cams;
  }
  for (int k = 0; k < n; ++k) {
    const RingSlot s = ring_slot(k, n);
    const double a = s.azimuth_deg * kRadPerDeg;
    const Vec3 center = robot_center_world + Vec3(s.distance_mm * std::sin(a),
                                                  -s.distance_mm * std::cos(a), s.height_mm);
    cams.push_back(look_at("cam" + std::to_string(k), kRingLenses[static_cast<std::size_t>(k)],
                           center, robot_center_world));
  }
  return cams;
}

}  // namespace mocap::sim
