// Design: the wand / L-frame scenes, the wand's path and the recording writer (see
// wand_sim.h). The scene reuses the shoulder scenario's rig and imaging (make_scene)
// so the calibration recordings are seen by exactly the rig the other recordings use.
// Bodies: 0 = the calibration object, 1 = the room (static glints only).
// The folder set-up and the render of every camera (2..32) + PGM writing are
// frame_writer.h's.
#include "sim/wand_sim.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/rotation.h"
#include "core/units.h"
#include "formats/csv_outputs.h"
#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "sim/frame_writer.h"
#include "sim/render.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Room glints: static shiny spots behind the volume, facing the cameras roughly.
void add_room_glints(SimScene& scene, int count, std::uint64_t seed) {
  Rng rng(hash_mix(seed, 0x726F6F6Dull));
  const double scale = static_cast<double>(scene.imaging.maxval) / 255.0;
  for (int g = 0; g < count; ++g) {
    GlintSpot spot;
    spot.body = 1;
    spot.point_body =
        Vec3(rng.uniform(-450.0, 450.0), rng.uniform(650.0, 900.0), rng.uniform(-330.0, 330.0));
    spot.normal_body = Vec3(rng.uniform(-0.4, 0.4), -1.0, rng.uniform(-0.4, 0.4)).normalized();
    spot.peak_dn = rng.uniform(150.0, 255.0) * scale;
    for (auto& lobe : spot.lobes) {
      lobe = Vec3(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(0.5, 1.3));
    }
    spot.lobes[0].head<2>().setZero();
    scene.glints.push_back(spot);
  }
}

Expected<SimScene> make_calib_scene(const SimOptions& options, CalibObjectKind kind,
                                    const CalibrationObjects& obj) {
  auto base = make_scene(options);
  if (!base) return base.error();
  SimScene scene;
  scene.rig = base->rig;
  scene.imaging = base->imaging;
  scene.marker_radius_mm = 0.5 * obj.wand.marker_diameter_mm;
  MarkerTarget object;
  if (kind == CalibObjectKind::kWand) {
    object.name = "wand";
    const double mid = 0.5 * (obj.wand.markers_mm.front() + obj.wand.markers_mm.back());
    for (double s : obj.wand.markers_mm) object.markers_body.push_back(Vec3(s - mid, 0.0, 0.0));
    const double x0 = obj.wand.markers_mm.front() - mid;
    // The rod: one segment between neighbouring balls, from surface to surface.
    const double r = scene.marker_radius_mm;
    for (std::size_t k = 0; k + 1 < object.markers_body.size(); ++k) {
      scene.capsules.push_back(Capsule{0, object.markers_body[k] + Vec3(r + 2.5, 0, 0),
                                       object.markers_body[k + 1] - Vec3(r + 2.5, 0, 0), 2.5,
                                       false});
    }
    scene.capsules.push_back(
        Capsule{0, Vec3(x0 - 25.0, 0, 0), Vec3(x0 - 170.0, 0, 0), 14.0, false});  // handle
    scene.T_world_body_ref = {wand_pose(0, 1, options.seed), Iso3::Identity()};
  } else {
    object.name = "lframe";
    scene.marker_radius_mm = 0.5 * obj.lframe.marker_diameter_mm;
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
    for (const Vec3& p : obj.lframe.markers_mm) {
      object.markers_body.push_back(p);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      // A short stalk from the bar up to the ball.
      scene.capsules.push_back(
          Capsule{0, Vec3(p.x(), p.y(), -14.0), Vec3(p.x(), p.y(), 0.0), 2.0, false});
    }
    scene.capsules.push_back(
        Capsule{0, Vec3(lo.x(), 0, -22.0), Vec3(hi.x() + 20.0, 0, -22.0), 8.0, false});
    scene.capsules.push_back(
        Capsule{0, Vec3(0, lo.y(), -22.0), Vec3(0, hi.y() + 20.0, -22.0), 8.0, false});
    scene.T_world_body_ref = {simulated_T_world_lframe(), Iso3::Identity()};
  }
  scene.targets.marker_diameter_mm = 2.0 * scene.marker_radius_mm;
  for (std::size_t m = 0; m < object.markers_body.size(); ++m) {
    scene.marker_body.push_back(0);
    scene.marker_index.push_back(static_cast<int>(m));
  }
  scene.targets.bodies.push_back(object);
  scene.targets.bodies.push_back(MarkerTarget{"room", {}});
  add_room_glints(scene, options.stray, options.seed);
  return scene;
}

}  // namespace

CalibrationObjects default_calibration_objects() {
  CalibrationObjects obj;
  obj.wand.markers_mm = {0.0, 110.0, 300.0};
  obj.wand.marker_diameter_mm = 12.0;
  obj.has_lframe = true;
  obj.lframe.markers_mm = {Vec3(0, 0, 0), Vec3(400, 0, 0), Vec3(0, 250, 0), Vec3(200, 0, 0)};
  obj.lframe.marker_diameter_mm = 12.0;
  return obj;
}

Iso3 simulated_T_world_lframe() {
  return make_iso(rot_z(12.0 * kRadPerDeg), Vec3(-170.0, 130.0, -215.0));
}

Rig rig_in_lframe(const Rig& rig, const Iso3& T_world_lframe) {
  Rig out = rig;
  for (CameraModel& c : out.cameras) {
    const Iso3 T = c.T_cam_world() * T_world_lframe;
    c.R_cam_world = T.linear();
    c.t_cam_world = T.translation();
  }
  return out;
}

Iso3 wand_pose(int frame, int frames, std::uint64_t seed) noexcept {
  // Phases from the seed; frequencies in cycles over the whole recording.
  std::array<double, 6> ph{};
  std::uint64_t key = hash_mix(seed, 0x77616E64ull);
  for (double& p : ph) {
    key = hash_mix(key, 1);
    p = 2.0 * kPi * hash_uniform(key);
  }
  const double u = frames > 1 ? static_cast<double>(frame) / static_cast<double>(frames - 1) : 0.0;
  const double tau = 2.0 * kPi * u;
  const Vec3 center(0.0 + 300.0 * std::sin(3.1 * tau + ph[0]) + 40.0 * std::sin(7.3 * tau + ph[3]),
                    300.0 + 210.0 * std::sin(2.3 * tau + ph[1]),
                    10.0 + 215.0 * std::sin(4.3 * tau + ph[2]) + 30.0 * std::sin(9.1 * tau));
  // Direction: mostly across the view (in-image rotation theta), tilted in depth by psi.
  const double theta = 2.0 * kPi * 2.6 * u + 0.6 * std::sin(5.7 * tau + ph[4]);
  const double psi = 0.55 * std::sin(6.1 * tau + ph[5]);
  const Vec3 d(std::cos(theta) * std::cos(psi), std::sin(psi), std::sin(theta) * std::cos(psi));
  // Any roll about the axis: build a frame with x = d.
  const Vec3 helper = std::fabs(d.y()) < 0.9 ? Vec3::UnitY() : Vec3::UnitX();
  const Vec3 y = helper.cross(d).normalized();
  const Vec3 z = d.cross(y);
  Mat3 R;
  R.col(0) = d;
  R.col(1) = y;
  R.col(2) = z;
  const Mat3 roll = Eigen::AngleAxisd(1.7 * tau, Vec3::UnitX()).toRotationMatrix();
  return make_iso(R * roll, center);
}

Expected<SimSummary> write_calibration_recording(const SimOptions& options, CalibObjectKind kind,
                                                 const std::string& dir,
                                                 const std::function<void(int)>& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  if (options.frames < 1 || options.frames > 1000000)
    return make_error("simulate", "frames", "must be 1..1000000");
  if (!(options.fps > 0.0)) return make_error("simulate", "fps", "must be > 0");
  const CalibrationObjects obj = default_calibration_objects();
  auto scene_r = make_calib_scene(options, kind, obj);
  if (!scene_r) return scene_r.error();
  const SimScene& scene = *scene_r;
  const Rig& rig = scene.rig;
  if (auto frames = begin_recording(dir, rig, options.frames, options.fps); !frames)
    return frames.error();
  for (auto r : {save_rig(dir + "/gt/rig_true.yaml", rig),
                 save_calibration_objects(dir + "/wand.yaml", obj)}) {
    if (!r) return r.error();
  }
  if (kind == CalibObjectKind::kLFrame) {
    if (auto r = save_rig(dir + "/gt/rig_lframe_true.yaml",
                          rig_in_lframe(rig, simulated_T_world_lframe()));
        !r)
      return r.error();
  }
  const int n_cams = static_cast<int>(rig.cameras.size());
  auto markers_csv =
      CsvFile::open(dir + "/gt/markers.csv",
                    ("frame,marker,x,y,z," + markers_csv_camera_columns(n_cams, false)).c_str());
  if (!markers_csv) return markers_csv.error();

  auto renderer = MultiRender::create(scene, options.threads);
  if (!renderer) return renderer.error();
  std::vector<const CameraViews*> ws;
  for (int c = 0; c < n_cams; ++c) ws.push_back(&renderer->views(c));
  std::vector<Image> images = make_camera_images(scene);
  SceneState state = make_state(scene);
  SimSummary summary;
  summary.frames = options.frames;
  summary.cameras = n_cams;
  for (int f = 0; f < options.frames; ++f) {
    if (kind == CalibObjectKind::kWand)
      state.T_world_body[0] = wand_pose(f, options.frames, options.seed);
    state.noise_key = frame_noise_key(options.seed, f);
    auto rendered = renderer->render(state, images, [&](int c) {
      const auto uc = static_cast<std::size_t>(c);
      return write_pgm(frame_file_path(dir, rig.cameras[uc].name, f), images[uc].view());
    });
    if (!rendered) return rendered.error();
    for (int m = 0; m < scene.marker_count(); ++m) {
      const auto um = static_cast<std::size_t>(m);
      const Vec3 X = state.T_world_body[0] * scene.marker_in_body(m);
      std::fprintf(markers_csv->handle(), "%d,%d,%.6f,%.6f,%.6f", f, m, X.x(), X.y(), X.z());
      for (const CameraViews* w : ws)
        write_marker_view(markers_csv->handle(), w->markers[um], summary);
      std::fputc('\n', markers_csv->handle());
    }
    for (const CameraViews* w : ws) {
      for (int s = 0; s < w->stray_count; ++s) {
        summary.stray_blobs +=
            w->strays[static_cast<std::size_t>(s)].kind == StrayKind::kGlint ? 1 : 0;
      }
    }
    if (progress) progress(f + 1);
  }
  if (auto r = markers_csv->close(); !r) return r.error();
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return summary;
}

}  // namespace mocap::sim
