#include "track/offline_tracker.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/rotation.h"
#include "core/units.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "track/frame_source.h"
#include "track/labelled_markers.h"
#include "track/trajectory_export.h"

namespace mocap {
namespace {}  // namespace

Expected<OfflineTrackResult> track_recording(const OfflineTrackOptions& opt) {
  auto rec = Recording::open(opt.recording_dir);
  if (!rec) return rec.error();
  auto targets = load_targets(opt.targets_path);
  if (!targets) return targets.error();
  std::optional<JointModel> model;
  if (!opt.model_path.empty()) {
    auto m = load_model(opt.model_path, *targets);
    if (!m) return m.error();
    model = std::move(m).value();
  }
  auto proc = FrameProcessor::create(rec->rig(), *targets, model ? &*model : nullptr, opt.config);
  if (!proc) {  // name the file the problem comes from (the spec's "file: key: problem")
    const std::string& m = proc.error().message;
    if (m.rfind("rig: ", 0) == 0)
      return make_error(opt.recording_dir + "/rig.yaml", "cameras", m.substr(5));
    if (m.rfind("identification: ", 0) == 0) return make_error(opt.targets_path, "", m);
    if (m.rfind("joint angles: ", 0) == 0 || m.rfind("chain tracking: ", 0) == 0)
      return make_error(opt.model_path, "", m);
    return make_error(opt.recording_dir, "", m);
  }
  for (const std::string& w : proc->warnings()) {
    if (opt.warn) opt.warn(opt.targets_path + ": " + w);
  }
  for (const std::string& w : rec->warnings()) {  // a blob file's torn tail, damaged chunks
    if (opt.warn) opt.warn(w);
  }

  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec) return make_error(opt.out_dir, "", "cannot create output folder: " + ec.message());
  // More than two cameras: points.csv adds the spec's `cameras` column.
  const bool multi_camera = rec->rig().cameras.size() > 2;
  auto points_csv = open_points_csv(opt.out_dir + "/points.csv", multi_camera);
  if (!points_csv) return points_csv.error();
  auto poses_csv = open_poses_csv(opt.out_dir + "/poses.csv");
  if (!poses_csv) return poses_csv.error();
  std::optional<CsvFile> angles_csv;
  if (model) {
    auto a = open_angles_csv(opt.out_dir + "/angles.csv");
    if (!a) return a.error();
    angles_csv.emplace(std::move(a).value());
  }
  auto exports = LabelledExports::open({opt.out_dir + "/markers.csv", opt.c3d_path, opt.trc_path},
                                       *targets, rec->frames(), opt.recording_dir + "/frames.csv");
  if (!exports) return exports.error();
  auto labelled = std::make_unique<LabelledMarkers>();

  const auto& frames = rec->frames();
  OfflineTrackResult result;
  result.stats = std::make_unique<TrackStats>();
  result.stats->reserve(rec->frames().size());
  for (const MarkerTarget& t : targets->bodies) result.body_names.push_back(t.name);
  result.body_found.assign(targets->bodies.size(), 0);
  if (model) {
    for (const JointSpec& j : model->joints) result.joint_names.push_back(j.name);
    result.joint_poses.assign(model->joints.size(), 0);
    result.joint_chain.assign(model->joints.size(), 0);
  }

  FrameOutput out = proc->make_output();
  // Detection on the two cores, as live (detect_workers.h), or the blob lists of a blob
  // recording (frame_source.h).
  FrameSource source(*rec, *proc, opt.detect_threads);
  PointRow point_row;
  PoseRow pose_row;
  AngleRow angle_row;
  for (std::size_t fi = 0; fi < frames.size(); ++fi) {
    const FrameEntry& fe = frames[fi];
    const FrameSource::Result loaded = source.process(fe, out);
    const bool missing = loaded.missing > 0;
    const bool damaged = loaded.damaged > 0;
    if (damaged && opt.warn)
      opt.warn(loaded.problem + " (frame " + std::to_string(fe.frame) + " treated as dropped)");
    result.frames_missing += missing ? 1 : 0;
    result.frames_damaged += damaged ? 1 : 0;

    result.stats->record(out.times);
    ++result.stats->frames;
    ++result.frames;

    for (int i = 0; i < out.points.size(); ++i) {
      const Point3& p = out.points[i];
      if (!p.reported) continue;  // lost its blob to a better candidate (point_selection.h)
      point_row.frame = fe.frame;
      point_row.X_world = p.X_world;
      point_row.reproj_px = p.reproj_px;
      point_row.cameras = multi_camera ? p.blob_index.count() : 0;
      write_row(*points_csv, point_row);
      ++result.points;
    }
    for (int b = 0; b < out.poses.count; ++b) {
      const BodyPose& body = out.poses.bodies[static_cast<std::size_t>(b)];
      if (!body.found) continue;
      ++result.body_found[static_cast<std::size_t>(b)];
      pose_row.frame = fe.frame;
      pose_row.timestamp_ns = fe.timestamp_ns;
      pose_row.body = targets->bodies[static_cast<std::size_t>(b)].name;
      pose_row.q_world_body = canonical_quat(body.T_world_body.linear());
      pose_row.t_world_body = body.T_world_body.translation();
      pose_row.markers = body.markers;
      pose_row.rms_mm = body.rms_mm;
      const auto ub = static_cast<std::size_t>(b);
      pose_row.has_velocity = ub < out.body_rates.size() && out.body_rates[ub].valid;
      if (pose_row.has_velocity) {
        const kinematics::BodyRate& r = out.body_rates[ub];
        pose_row.v_world_mm_s = r.v_world_mm_s;
        pose_row.w_world_deg_s = r.w_world_rad_s * kDegPerRad;
        pose_row.v_sd_mm_s = r.v_sd_mm_s;
        pose_row.w_sd_deg_s = r.w_sd_rad_s * kDegPerRad;
      }
      write_row(*poses_csv, pose_row);
    }
    if (angles_csv) {
      for (std::size_t j = 0; j < out.angles.joints.size(); ++j) {
        const kinematics::JointAngle& a = out.angles.joints[j];
        if (!a.valid) continue;
        angle_row.frame = fe.frame;
        angle_row.timestamp_ns = fe.timestamp_ns;
        angle_row.joint = model->joints[j].name;
        angle_row.type = a.type;
        angle_row.angles_deg = Vec3(a.a0, a.a1, a.a2) * kDegPerRad;
        angle_row.q_parent_child = a.q_parent_child;
        angle_row.solved_by = client::solved_by_name(a.solved_by);
        if (a.solved_by == client::SolvedBy::kChain)
          ++result.joint_chain[j];
        else
          ++result.joint_poses[j];
        angle_row.sd_deg = Vec3(a.sd_rad[0], a.sd_rad[1], a.sd_rad[2]) * kDegPerRad;
        angle_row.has_rates = a.rate_valid;
        angle_row.rate_deg_s = Vec3(a.rate_rad_s[0], a.rate_rad_s[1], a.rate_rad_s[2]) * kDegPerRad;
        angle_row.rate_sd_deg_s =
            Vec3(a.rate_sd_rad_s[0], a.rate_sd_rad_s[1], a.rate_sd_rad_s[2]) * kDegPerRad;
        write_row(*angles_csv, angle_row);
        ++result.angle_rows;
      }
    }
    label_markers(out, *targets, *labelled);
    if (!exports->write_frame(fi, *labelled)) break;  // close() below names the file
    if (opt.progress)
      opt.progress(static_cast<std::int64_t>(fi + 1), static_cast<std::int64_t>(frames.size()));
  }

  if (auto r = points_csv->close(); !r) return r.error();
  if (auto r = poses_csv->close(); !r) return r.error();
  if (angles_csv) {
    if (auto r = angles_csv->close(); !r) return r.error();
  }
  if (auto r = exports->close(); !r) return r.error();
  result.marker_rows = exports->marker_rows();
  result.stats->counters = collect_counters(*proc);
  if (!opt.stats_path.empty()) {
    if (auto r = write_stats_json(opt.stats_path, *result.stats); !r) return r.error();
  }
  if (!opt.truth_dir.empty()) {
    auto gt = load_ground_truth(opt.truth_dir);
    if (!gt) return gt.error();
    auto pts = read_points_csv(opt.out_dir + "/points.csv");
    if (!pts) return pts.error();
    auto poses = read_poses_csv(opt.out_dir + "/poses.csv");
    if (!poses) return poses.error();
    std::vector<AngleRow> angles;
    if (model) {
      auto a = read_angles_csv(opt.out_dir + "/angles.csv");
      if (!a) return a.error();
      angles = std::move(a).value();
    }
    result.accuracy = evaluate_against_truth(*gt, *pts, *poses, angles);
  }
  return result;
}

std::string format_track_summary(const OfflineTrackResult& r) {
  std::string s;
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      "tracked %lld frames (%lld with a missing camera frame, %lld damaged), %lld 3D points\n",
      static_cast<long long>(r.frames), static_cast<long long>(r.frames_missing),
      static_cast<long long>(r.frames_damaged), static_cast<long long>(r.points));
  s += buf;
  for (std::size_t b = 0; b < r.body_names.size(); ++b) {
    std::snprintf(buf, sizeof buf, "  %-10s found in %lld frames (%.1f%%)\n",
                  r.body_names[b].c_str(), static_cast<long long>(r.body_found[b]),
                  r.frames
                      ? 100.0 * static_cast<double>(r.body_found[b]) / static_cast<double>(r.frames)
                      : 0.0);
    s += buf;
  }
  if (!r.joint_names.empty()) {
    s += "  joint coverage (share of frames with the angle valid):  valid    poses    chain\n";
    const double n = r.frames > 0 ? static_cast<double>(r.frames) : 1.0;
    for (std::size_t j = 0; j < r.joint_names.size(); ++j) {
      const double p = 100.0 * static_cast<double>(r.joint_poses[j]) / n;
      const double c = 100.0 * static_cast<double>(r.joint_chain[j]) / n;
      std::snprintf(buf, sizeof buf, "    %-12s %41.1f%% %7.1f%% %7.1f%%\n",
                    r.joint_names[j].c_str(), p + c, p, c);
      s += buf;
    }
  }
  if (r.stats) {
    const std::pair<const char*, const LatencySamples*> stages[] = {
        {"load", &r.stats->load},
        {"detect", &r.stats->detect},
        {"triangulate", &r.stats->triangulate},
        {"identify", &r.stats->identify},
        {"angles", &r.stats->angles},
        {"frame", &r.stats->frame}};
    s += r.stats->frame.exact()
             ? "  latency per frame (us):       p50        p99        max\n"
             : "  latency per frame (us, histogram percentiles: at most 1/64 above):\n"
               "                               p50        p99        max\n";
    for (const auto& [name, rec] : stages) {
      const LatencyStats l = rec->stats();
      std::snprintf(buf, sizeof buf, "    %-12s %14.1f %10.1f %10.1f\n", name, l.p50_us, l.p99_us,
                    l.max_us);
      s += buf;
    }
  }
  if (r.accuracy) s += format_accuracy(*r.accuracy);
  return s;
}

}  // namespace mocap
