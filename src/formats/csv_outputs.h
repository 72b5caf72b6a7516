// Design: the spec's output CSV files (points.csv, poses.csv, angles.csv): row types,
// streaming writers (header first, one row per item, fixed precision, '\n' line ends)
// and readers used by evaluation scripts and tests. Angles are written in degrees;
// quaternions with qw >= 0.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"

namespace mocap {

struct PointRow {
  std::int64_t frame = 0;
  Vec3 X_world = Vec3::Zero();
  double reproj_px = 0.0;
  // Cameras that saw the point (the extension column `cameras`); 0: not written/read.
  int cameras = 0;
};

struct PoseRow {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::string body;
  Quat q_world_body = Quat::Identity();
  Vec3 t_world_body = Vec3::Zero();
  int markers = 0;
  double rms_mm = 0.0;
  // Extension columns (2027-01): the live tracker's causal velocity of the body origin
  // vx,vy,vz (mm/s) and angular velocity wx,wy,wz (deg/s), both in the world frame, and
  // their sds sd_vx..sd_wz, written empty while not known. Files without them read as none.
  bool has_velocity = false;
  Vec3 v_world_mm_s = Vec3::Zero();
  Vec3 w_world_deg_s = Vec3::Zero();
  Vec3 v_sd_mm_s = Vec3::Zero();
  Vec3 w_sd_deg_s = Vec3::Zero();
};

struct AngleRow {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::string joint;
  JointType type = JointType::kBall;
  Vec3 angles_deg = Vec3::Zero();  // hinge: (angle, 0, 0)
  Quat q_parent_child = Quat::Identity();
  // Extension columns (2026-12): how the angle was solved ("poses" or "chain") and the
  // standard deviations of a0..a2 in degrees ("truth" in the simulator's gt/angles.csv;
  // written as "none" when empty). Files without them read as "" and 0.
  std::string solved_by;
  Vec3 sd_deg = Vec3::Zero();
  // Extension columns (2027-01): da0,da1,da2 (deg/s, the live tracker's causal rates of
  // a0..a2) and sd_da0,sd_da1,sd_da2, written empty while no rate is known.
  bool has_rates = false;
  Vec3 rate_deg_s = Vec3::Zero();
  Vec3 rate_sd_deg_s = Vec3::Zero();
};

// A CSV file opened for writing; the header is written at open.
class CsvFile {
 public:
  static Expected<CsvFile> open(const std::string& path, const char* header);
  CsvFile(CsvFile&&) noexcept = default;
  CsvFile& operator=(CsvFile&&) noexcept = default;
  ~CsvFile() = default;
  std::FILE* handle() const noexcept { return file_.get(); }
  const std::string& path() const noexcept { return path_; }
  // Flushes and closes; an Error when the data could not be written (disk full...).
  Expected<void> close();

 private:
  CsvFile() = default;
  struct Closer {
    void operator()(std::FILE* f) const noexcept {
      if (f) std::fclose(f);
    }
  };
  std::unique_ptr<std::FILE, Closer> file_;
  std::string path_;
};

// with_cameras: the header ends with the extension column `cameras` (rigs of more than
// two cameras); rows then carry PointRow::cameras.
Expected<CsvFile> open_points_csv(const std::string& path, bool with_cameras = false);
Expected<CsvFile> open_poses_csv(const std::string& path);
Expected<CsvFile> open_angles_csv(const std::string& path);
void write_row(CsvFile& f, const PointRow& r) noexcept;
void write_row(CsvFile& f, const PoseRow& r) noexcept;
void write_row(CsvFile& f, const AngleRow& r) noexcept;

Expected<std::vector<PointRow>> read_points_csv(const std::string& path);
Expected<std::vector<PoseRow>> read_poses_csv(const std::string& path);
Expected<std::vector<AngleRow>> read_angles_csv(const std::string& path);

}  // namespace mocap
