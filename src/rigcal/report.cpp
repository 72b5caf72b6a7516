// Design: see report.h.
#include "rigcal/report.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace mocap::rigcal {
namespace {

// v with `digits` decimals.
std::string num(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string quoted(const std::string& s) {
  std::string o = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') o += '\\';
    o += ch;
  }
  return o + "\"";
}

}  // namespace

std::string format_report_yaml(const RigCalResult& r, const RigCalOptions& opt) {
  std::string s = "# mocap calibrate-rig quality report (docs/rig_calibration.md)\n";
  s += "frames_total: " + std::to_string(r.frames_total) + "\n";
  s += "camera_count: " + std::to_string(r.cameras.size()) + "\n";
  s += "frames_wand_in_both: " + std::to_string(r.frames_both) + "\n";
  s += "frames_used: " + std::to_string(r.frames_used) + "\n";
  s += "essential_inliers: " + std::to_string(r.essential_inliers) + "\n";
  s += "baseline_mm: " + num(r.baseline_mm, 4) + "\n";
  s += "intrinsics_refined: " + std::string(r.intrinsics_refined ? "true" : "false") + "\n";
  s += "intrinsics_note: " + quoted(r.intrinsics_note) + "\n";
  s += "bundle: {iterations: " + std::to_string(r.bundle.iterations) +
       ", converged: " + (r.bundle.converged ? "true" : "false") +
       ", frames_dropped: " + std::to_string(r.bundle.frames_dropped) + "}\n";
  s += "wand_length_error_mm: {mean: " + num(r.wand_length_mean_error_mm, 4) +
       ", rms: " + num(r.wand_length_rms_error_mm, 4) +
       ", samples: " + std::to_string(r.wand_length_samples) + "}\n";
  // wand_centres: the whole end balls; wand_centres_partly_hidden: those whose blob was
  // less round than a whole ball's (their own cut).
  auto centres = [&](const std::string& name, const RodCutChoice& w) {
    if (w.end_ball_views == 0) return;
    const std::string indent(name.size() + 3, ' ');
    s += name + ": {rod_cut_deg: " + num(w.cut_deg, 0) +
         ", chosen_from_recording: " + (w.from_recording ? "true" : "false") +
         ", end_ball_views: " + std::to_string(w.end_ball_views) +
         ", outer_rim_used: " + num(w.outer_rim_used, 3) + ",\n";
    auto list = [&](const char* key, const auto& values, int digits, bool last) {
      s += indent + key + ": [";
      for (std::size_t j = 0; j < values.size(); ++j) s += (j ? ", " : "") + num(values[j], digits);
      s += last ? "]}\n" : "],\n";
    };
    list("cuts_deg", kRodCutsDeg, 0, false);
    list("mean_shift_px", w.mean_shift_px, 5, false);
    list("standard_error_px", w.standard_error_px, 5, false);
    list("along_sd_px", w.along_sd_px, 5, true);
  };
  centres("wand_centres", r.wand_centres);
  centres("wand_centres_partly_hidden", r.wand_centres_partly_hidden);
  s += "cameras:\n";
  for (const CameraQuality& q : r.quality) {
    s += "  - name: " + quoted(q.name) + "\n";
    s += "    frames_labelled: " + std::to_string(q.frames_labelled) + "\n";
    s += "    label_rejections: {too_few_blobs: " + std::to_string(q.label_status[1]) +
         ", too_many_blobs: " + std::to_string(q.label_status[2]) +
         ", no_wand: " + std::to_string(q.label_status[3]) +
         ", ambiguous: " + std::to_string(q.label_status[4]) + "}\n";
    s += "    reprojection_rms_px: " + num(q.reprojection_rms_px, 4) + "\n";
    s += "    coverage: " + num(q.coverage, 3) + "   # occupied cells of a " +
         std::to_string(opt.coverage_cols) + "x" + std::to_string(opt.coverage_rows) + " grid\n";
    s += "    coverage_png: " + quoted("coverage_" + q.name + ".png") + "\n";
    // Added for rigs of more than two cameras (present for every rig).
    s += "    frames_used: " + std::to_string(q.frames_used) + "\n";
    s += "    intrinsics_refined: " + std::string(q.intrinsics_refined ? "true" : "false") + "\n";
    s += "    initialised_from: " + quoted(q.initialised_from) + "\n";
    s += "    essential_inliers: " + std::to_string(q.essential_inliers) + "\n";
    const Mat3 R = q.T_cam_cam0.linear();
    const Vec3 t = q.T_cam_cam0.translation();
    s += "    baseline_mm: " + num(q.baseline_mm, 4) + "   # centre's distance from camera 0\n";
    s += "    rotation_from_cam0_deg: " +
         num(Eigen::AngleAxisd(R).angle() * 180.0 / 3.14159265358979323846, 4) + "\n";
    s += "    R_cam_cam0: [";
    for (int i = 0; i < 9; ++i) s += (i ? ", " : "") + num(R(i / 3, i % 3), 9);
    s += "]   # X_cam = R X_cam0 + t\n";
    s += "    t_cam_cam0_mm: [" + num(t.x(), 4) + ", " + num(t.y(), 4) + ", " + num(t.z(), 4) +
         "]\n";
  }
  if (r.has_ground) {
    s += "ground_frame: {rms_mm: " + num(r.ground.rms_mm, 4) +
         ", frames: " + std::to_string(r.ground.frames) + "}\n";
  }
  s += "warnings:";
  if (r.warnings.empty()) s += " []";
  s += "\n";
  for (const std::string& w : r.warnings) s += "  - " + quoted(w) + "\n";
  return s;
}

RgbImage coverage_image(const CameraQuality& q, const CameraModel& cam, int cols, int rows) {
  const int W = std::max(1, cam.width / 2), H = std::max(1, cam.height / 2);
  RgbImage img(W, H);
  std::vector<bool> cell(static_cast<std::size_t>(cols * rows), false);
  for (const Vec2& p : q.wand_points_px) {
    const int cx = std::clamp(static_cast<int>(p.x() * cols / cam.width), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y() * rows / cam.height), 0, rows - 1);
    cell[static_cast<std::size_t>(cy * cols + cx)] = true;
  }
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const int cx = std::min(x * cols / W, cols - 1), cy = std::min(y * rows / H, rows - 1);
      const bool on = cell[static_cast<std::size_t>(cy * cols + cx)];
      const bool grid = (x * cols) % W < cols || (y * rows) % H < rows;
      const auto v = static_cast<std::uint8_t>(grid ? 70 : 25);
      img.set(x, y, v, static_cast<std::uint8_t>(on ? v + 60 : v), v);
    }
  }
  for (const Vec2& p : q.wand_points_px) {
    const int x = static_cast<int>(p.x() * 0.5), y = static_cast<int>(p.y() * 0.5);
    img.set(x, y, 255, 255, 255);
  }
  return img;
}

Expected<void> write_report(const std::string& dir, const RigCalResult& r,
                            const RigCalOptions& opt) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return make_error(dir, "", "cannot create directory: " + ec.message());
  const std::string path = dir + "/report.yaml";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return make_error(path, "", "cannot write");
  const std::string text = format_report_yaml(r, opt);
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) return make_error(path, "", "cannot write: I/O error");
  for (std::size_t c = 0; c < r.quality.size() && c < r.cameras.size(); ++c) {
    auto w =
        write_png(dir + "/coverage_" + r.quality[c].name + ".png",
                  coverage_image(r.quality[c], r.cameras[c], opt.coverage_cols, opt.coverage_rows));
    if (!w) return w.error();
  }
  return {};
}

}  // namespace mocap::rigcal
