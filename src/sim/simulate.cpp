// Design: the recording writer. Per frame: forward kinematics, one render per camera
// (MultiRender, frame_writer.h: 2..32 cameras, the odd ones on a second thread with its
// own workspace when threads = 2; results are identical either way because every
// random draw is keyed by seed, frame and camera), the PGM files, then the
// ground-truth rows (per-camera columns for every camera). Files are written with
// mocap_formats.
#include "sim/simulate.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/rotation.h"
#include "core/units.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"
#include "sim/frame_writer.h"
#include "sim/render.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

Quat hinge_zero(const JointSpec& joint) {
  for (const auto& [key, values] : joint.extra) {
    if (key == "zero_q_parent_child" && values.size() == 4) {
      return Quat(values[0], values[1], values[2], values[3]).normalized();
    }
  }
  return Quat::Identity();
}

const char* stray_name(StrayKind k) { return k == StrayKind::kGlint ? "glint" : "streak"; }

}  // namespace

Vec3 joint_angles_rad(const JointSpec& joint, const Iso3& T_world_parent,
                      const Iso3& T_world_child) {
  const Mat3 R_rel = T_world_parent.linear().transpose() * T_world_child.linear();
  if (joint.type == JointType::kBall) return rotation_to_euler_xyz(R_rel);
  const Mat3 Rd = R_rel * hinge_zero(joint).toRotationMatrix().transpose();
  const Vec3 v(Rd(2, 1) - Rd(1, 2), Rd(0, 2) - Rd(2, 0), Rd(1, 0) - Rd(0, 1));  // 2 sin(a) axis
  const double angle =
      std::atan2(0.5 * v.dot(joint.axis_parent.normalized()), 0.5 * (Rd.trace() - 1.0));
  return Vec3(angle, 0.0, 0.0);
}

MotionSpec motion_spec(const SimOptions& options) {
  MotionSpec spec;
  spec.kind = options.motion;
  spec.frames = options.frames;
  spec.fps = options.fps;
  spec.poses = options.poses;
  spec.seed = options.seed;
  return spec;
}

std::uint64_t frame_noise_key(std::uint64_t seed, std::int64_t frame) noexcept {
  return hash_mix(hash_mix(seed, 0x6672616D65ull), static_cast<std::uint64_t>(frame));
}

Expected<SimScene> make_scene(const SimOptions& o) {
  if (o.bits != 8 && o.bits != 16) return make_error("simulate", "bits", "must be 8 or 16");
  int maxval = o.maxval;
  if (maxval == 0) maxval = o.bits == 8 ? 255 : 4095;
  if (o.bits == 8 && maxval != 255)
    return make_error("simulate", "maxval", "must be 255 for 8-bit output");
  if (o.bits == 16 && (maxval < 256 || maxval > 65535))
    return make_error("simulate", "maxval", "must be 256..65535 for 16-bit output");
  SceneOptions so;
  so.kind = o.scene;
  so.cameras = o.cameras;  // 0: the scene's default
  if (!o.rig_path.empty()) {
    auto rig = load_rig(o.rig_path);
    if (!rig) return rig.error();
    if (o.cameras != 0 && static_cast<std::size_t>(o.cameras) != rig->cameras.size()) {
      return make_error("simulate", "cameras",
                        std::to_string(o.cameras) + " requested but the rig " + o.rig_path +
                            " has " + std::to_string(rig->cameras.size()));
    }
    so.rig = std::move(rig).value();
    so.rig_source = o.rig_path;
  }
  so.seed = o.seed;
  so.stray_glints = o.stray;
  so.imaging = default_imaging(o.bits, maxval);
  if (!(o.noise_dn < 0.0)) {
    if (!std::isfinite(o.noise_dn)) return make_error("simulate", "noise", "must be finite");
    so.imaging.read_noise_dn = o.noise_dn;
  }
  so.imaging.blur_sigma_px = o.blur_px;
  so.imaging.dropout_probability = o.dropout;
  so.imaging.streak = o.streak;
  return build_scene(so);
}

Expected<SimSummary> write_simulated_recording(const SimOptions& options, const std::string& dir,
                                               const std::function<void(int)>& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  auto scene_r = make_scene(options);
  if (!scene_r) return scene_r.error();
  const SimScene& scene = *scene_r;
  auto plan_r = plan_motion(scene, motion_spec(options));
  if (!plan_r) return plan_r.error();
  const MotionPlan& plan = *plan_r;

  auto frames_r = begin_recording(dir, scene.rig, options.frames, options.fps);
  if (!frames_r) return frames_r.error();
  const std::vector<FrameEntry>& frames = *frames_r;
  for (auto r : {save_targets(dir + "/targets.yaml", scene.targets),
                 save_model(dir + "/joints.yaml", joint_topology(scene)),
                 save_model(dir + "/gt/model_true.yaml", scene.joints_true)}) {
    if (!r) return r.error();
  }

  auto poses_csv = open_poses_csv(dir + "/gt/poses.csv");
  if (!poses_csv) return poses_csv.error();
  auto angles_csv = open_angles_csv(dir + "/gt/angles.csv");
  if (!angles_csv) return angles_csv.error();
  const int n_cams = static_cast<int>(scene.rig.cameras.size());
  auto markers_csv = CsvFile::open(
      dir + "/gt/markers.csv",
      ("frame,body,marker,x,y,z," + markers_csv_camera_columns(n_cams, true)).c_str());
  if (!markers_csv) return markers_csv.error();
  auto strays_csv = CsvFile::open(dir + "/gt/strays.csv", "frame,camera,kind,x,y,z,u,v,peak_dn");
  if (!strays_csv) return strays_csv.error();
  auto segments_csv =
      CsvFile::open(dir + "/gt/segments.csv", "segment,kind,first_frame,last_frame,tx,ty,tz");
  if (!segments_csv) return segments_csv.error();
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const MotionSegment& s = plan.segments[i];
    std::fprintf(segments_csv->handle(), "%zu,%s,%d,%d,%.6f,%.6f,%.6f\n", i, s.kind.c_str(),
                 s.first_frame, s.last_frame, s.robot_translation_mm.x(),
                 s.robot_translation_mm.y(), s.robot_translation_mm.z());
  }

  auto renderer = MultiRender::create(scene, options.threads);
  if (!renderer) return renderer.error();
  std::vector<Image> images = make_camera_images(scene);
  std::vector<const CameraViews*> results;
  for (int c = 0; c < n_cams; ++c) results.push_back(&renderer->views(c));
  SceneState state = make_state(scene);
  SimSummary summary;
  summary.frames = options.frames;
  summary.cameras = n_cams;

  for (int f = 0; f < options.frames; ++f) {
    apply_config(scene, plan.configs[static_cast<std::size_t>(f)], state);
    state.noise_key = frame_noise_key(options.seed, f);
    auto rendered = renderer->render(state, images, [&](int c) {
      const auto uc = static_cast<std::size_t>(c);
      return write_pgm(frame_file_path(dir, scene.rig.cameras[uc].name, f), images[uc].view());
    });
    if (!rendered) return rendered.error();
    const std::int64_t ts = frames[static_cast<std::size_t>(f)].timestamp_ns;
    for (int b = 0; b < scene.body_count(); ++b) {
      const Iso3& T = state.T_world_body[static_cast<std::size_t>(b)];
      PoseRow row;
      row.frame = f;
      row.timestamp_ns = ts;
      row.body = scene.targets.bodies[static_cast<std::size_t>(b)].name;
      row.q_world_body = canonical_quat(T.linear());
      row.t_world_body = T.translation();
      row.markers =
          static_cast<int>(scene.targets.bodies[static_cast<std::size_t>(b)].markers_body.size());
      row.rms_mm = 0.0;
      write_row(*poses_csv, row);
    }
    for (const JointSpec& j : scene.joints_true.joints) {
      const Iso3& Tp = state.T_world_body[static_cast<std::size_t>(j.parent_index)];
      const Iso3& Tc = state.T_world_body[static_cast<std::size_t>(j.child_index)];
      AngleRow row;
      row.frame = f;
      row.timestamp_ns = ts;
      row.joint = j.name;
      row.type = j.type;
      row.angles_deg = joint_angles_rad(j, Tp, Tc) * kDegPerRad;
      row.q_parent_child = canonical_quat(Tp.linear().transpose() * Tc.linear());
      row.solved_by = "truth";  // ground truth: exact, sd 0
      write_row(*angles_csv, row);
    }
    for (int m = 0; m < scene.marker_count(); ++m) {
      const auto um = static_cast<std::size_t>(m);
      const Vec3 X = state.T_world_body[static_cast<std::size_t>(scene.marker_body[um])] *
                     scene.marker_in_body(m);
      std::fprintf(
          markers_csv->handle(), "%d,%s,%d,%.6f,%.6f,%.6f", f,
          scene.targets.bodies[static_cast<std::size_t>(scene.marker_body[um])].name.c_str(),
          scene.marker_index[um], X.x(), X.y(), X.z());
      for (const CameraViews* r : results)
        write_marker_view(markers_csv->handle(), r->markers[um], summary);
      for (const CameraViews* r : results) {
        const MarkerView& mv = r->markers[um];
        const double total = mv.visible_area_px + mv.occluded_area_px;
        const double frac = (total > 0.0 && mv.inside_image) ? mv.visible_area_px / total : 0.0;
        std::fprintf(markers_csv->handle(), ",%.4f,%d,%d", frac, mv.merged ? 1 : 0,
                     mv.dropped ? 1 : 0);
      }
      std::fputc('\n', markers_csv->handle());
    }
    for (int c = 0; c < n_cams; ++c) {
      const CameraViews& r = *results[static_cast<std::size_t>(c)];
      for (int k = 0; k < r.stray_count; ++k) {
        const StrayView& s = r.strays[static_cast<std::size_t>(k)];
        std::fprintf(strays_csv->handle(), "%d,%d,%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.2f\n", f, c,
                     stray_name(s.kind), s.X_world.x(), s.X_world.y(), s.X_world.z(), s.px.x(),
                     s.px.y(), s.peak_dn);
        summary.stray_blobs += s.kind == StrayKind::kGlint ? 1 : 0;
      }
    }
    if (progress) progress(f + 1);
  }
  for (CsvFile* csv : {&*poses_csv, &*angles_csv, &*markers_csv, &*strays_csv, &*segments_csv}) {
    if (auto r = csv->close(); !r) return r.error();
  }
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return summary;
}

}  // namespace mocap::sim
