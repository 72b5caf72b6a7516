// Design: the output CSV files (see csv_outputs.h, docs/formats.md). Fixed precision:
// millimetres, pixels and degrees with 6 decimals, quaternion components with 9; the
// quaternion's sign is flipped when needed so that qw >= 0. Readers accept exactly what
// the writers produce (plus extra columns at the end) and name the line of any problem.
#include "formats/csv_outputs.h"

#include <cerrno>
#include <cstring>

#include "formats/csv_parse.h"
#include "formats/text_io.h"

namespace mocap {

using namespace formats_detail;

namespace {

constexpr const char* kPointsHeader = "frame,x,y,z,reproj_px";
constexpr const char* kPointsHeaderCameras = "frame,x,y,z,reproj_px,cameras";
constexpr const char* kPosesHeader = "frame,timestamp_ns,body,qw,qx,qy,qz,tx,ty,tz,markers,rms_mm";
// The header written: the spec's columns plus the 2027-01 extension columns (body velocities).
constexpr const char* kPosesHeaderWritten =
    "frame,timestamp_ns,body,qw,qx,qy,qz,tx,ty,tz,markers,rms_mm,"
    "vx,vy,vz,wx,wy,wz,sd_vx,sd_vy,sd_vz,sd_wx,sd_wy,sd_wz";
constexpr const char* kAnglesHeader = "frame,timestamp_ns,joint,type,a0,a1,a2,qw,qx,qy,qz";
// The header written: the spec's columns plus the 2026-12 and 2027-01 extension columns.
constexpr const char* kAnglesHeaderWritten =
    "frame,timestamp_ns,joint,type,a0,a1,a2,qw,qx,qy,qz,solved_by,sd_a0,sd_a1,sd_a2,"
    "da0,da1,da2,sd_da0,sd_da1,sd_da2";

Quat qw_positive(const Quat& q) noexcept {
  if (q.w() < 0.0) return Quat(-q.w(), -q.x(), -q.y(), -q.z());
  return q;
}

Quat read_quat(const CsvReader& r, std::size_t first) {
  return Quat(r.number(first), r.number(first + 1), r.number(first + 2), r.number(first + 3));
}

}  // namespace

Expected<CsvFile> CsvFile::open(const std::string& path, const char* header) {
  CsvFile f;
  f.path_ = path;
  errno = 0;
  f.file_.reset(std::fopen(path.c_str(), "w"));
  if (!f.file_) return make_error(path, "cannot write", std::strerror(errno));
  if (std::fputs(header, f.file_.get()) < 0 || std::fputc('\n', f.file_.get()) == EOF) {
    return make_error(path, "cannot write", std::strerror(errno));
  }
  return f;
}

Expected<void> CsvFile::close() {
  if (!file_) return {};
  std::FILE* f = file_.release();
  const bool had_error = std::fflush(f) != 0 || std::ferror(f) != 0;
  const int saved_errno = errno;
  const bool close_failed = std::fclose(f) != 0;
  if (had_error || close_failed) {
    return make_error(path_, "cannot write", std::strerror(had_error ? saved_errno : errno));
  }
  return {};
}

Expected<CsvFile> open_points_csv(const std::string& path, bool with_cameras) {
  return CsvFile::open(path, with_cameras ? kPointsHeaderCameras : kPointsHeader);
}
Expected<CsvFile> open_poses_csv(const std::string& path) {
  return CsvFile::open(path, kPosesHeaderWritten);
}
Expected<CsvFile> open_angles_csv(const std::string& path) {
  return CsvFile::open(path, kAnglesHeaderWritten);
}

void write_row(CsvFile& f, const PointRow& r) noexcept {
  if (!f.handle()) return;
  std::fprintf(f.handle(), "%lld,%.6f,%.6f,%.6f,%.6f", static_cast<long long>(r.frame),
               r.X_world.x(), r.X_world.y(), r.X_world.z(), r.reproj_px);
  if (r.cameras > 0)
    std::fprintf(f.handle(), ",%d\n", r.cameras);
  else
    std::fputc('\n', f.handle());
}

void write_row(CsvFile& f, const PoseRow& r) noexcept {
  if (!f.handle()) return;
  const Quat q = qw_positive(r.q_world_body);
  std::fprintf(f.handle(), "%lld,%lld,%s,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f,%d,%.6f",
               static_cast<long long>(r.frame), static_cast<long long>(r.timestamp_ns),
               r.body.c_str(), q.w(), q.x(), q.y(), q.z(), r.t_world_body.x(), r.t_world_body.y(),
               r.t_world_body.z(), r.markers, r.rms_mm);
  if (r.has_velocity) {
    const Vec3& v = r.v_world_mm_s;
    const Vec3& w = r.w_world_deg_s;
    const Vec3& sv = r.v_sd_mm_s;
    const Vec3& sw = r.w_sd_deg_s;
    std::fprintf(f.handle(), ",%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
                 v.x(), v.y(), v.z(), w.x(), w.y(), w.z(), sv.x(), sv.y(), sv.z(), sw.x(), sw.y(),
                 sw.z());
  } else {
    std::fputs(",,,,,,,,,,,,\n", f.handle());
  }
}

void write_row(CsvFile& f, const AngleRow& r) noexcept {
  if (!f.handle()) return;
  const Quat q = qw_positive(r.q_parent_child);
  std::fprintf(f.handle(), "%lld,%lld,%s,%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,%s,%.6f,%.6f,%.6f",
               static_cast<long long>(r.frame), static_cast<long long>(r.timestamp_ns),
               r.joint.c_str(), joint_type_name(r.type), r.angles_deg.x(), r.angles_deg.y(),
               r.angles_deg.z(), q.w(), q.x(), q.y(), q.z(),
               r.solved_by.empty() ? "none" : r.solved_by.c_str(), r.sd_deg.x(), r.sd_deg.y(),
               r.sd_deg.z());
  if (r.has_rates) {
    std::fprintf(f.handle(), ",%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", r.rate_deg_s.x(), r.rate_deg_s.y(),
                 r.rate_deg_s.z(), r.rate_sd_deg_s.x(), r.rate_sd_deg_s.y(), r.rate_sd_deg_s.z());
  } else {
    std::fputs(",,,,,,\n", f.handle());
  }
}

Expected<std::vector<PointRow>> read_points_csv(const std::string& path) {
  auto reader = CsvReader::open(path, kPointsHeader);
  if (!reader) return reader.error();
  return guard_fields<std::vector<PointRow>>(path, [&]() -> Expected<std::vector<PointRow>> {
    std::vector<PointRow> rows;
    CsvReader& r = *reader;
    while (r.next()) {
      PointRow p;
      p.frame = r.integer(0);
      p.X_world = Vec3(r.number(1), r.number(2), r.number(3));
      p.reproj_px = r.number(4);
      if (r.has_column(5)) p.cameras = static_cast<int>(r.integer(5));
      rows.push_back(p);
    }
    return rows;
  });
}

Expected<std::vector<PoseRow>> read_poses_csv(const std::string& path) {
  auto reader = CsvReader::open(path, kPosesHeader);
  if (!reader) return reader.error();
  return guard_fields<std::vector<PoseRow>>(path, [&]() -> Expected<std::vector<PoseRow>> {
    std::vector<PoseRow> rows;
    CsvReader& r = *reader;
    while (r.next()) {
      PoseRow p;
      p.frame = r.integer(0);
      p.timestamp_ns = r.integer(1);
      p.body = std::string(r.text(2));
      p.q_world_body = read_quat(r, 3);
      p.t_world_body = Vec3(r.number(7), r.number(8), r.number(9));
      const std::int64_t markers = r.integer(10);
      if (markers < 0 || markers > 1000000) fail(r.where(), "column 'markers': out of range");
      p.markers = static_cast<int>(markers);
      p.rms_mm = r.number(11);
      if (r.has_column(23) && !r.field_empty(12)) {
        p.has_velocity = true;
        p.v_world_mm_s = Vec3(r.number(12), r.number(13), r.number(14));
        p.w_world_deg_s = Vec3(r.number(15), r.number(16), r.number(17));
        p.v_sd_mm_s = Vec3(r.number(18), r.number(19), r.number(20));
        p.w_sd_deg_s = Vec3(r.number(21), r.number(22), r.number(23));
      }
      rows.push_back(std::move(p));
    }
    return rows;
  });
}

Expected<std::vector<AngleRow>> read_angles_csv(const std::string& path) {
  auto reader = CsvReader::open(path, kAnglesHeader);
  if (!reader) return reader.error();
  return guard_fields<std::vector<AngleRow>>(path, [&]() -> Expected<std::vector<AngleRow>> {
    std::vector<AngleRow> rows;
    CsvReader& r = *reader;
    while (r.next()) {
      AngleRow a;
      a.frame = r.integer(0);
      a.timestamp_ns = r.integer(1);
      a.joint = std::string(r.text(2));
      const std::string_view type = r.text(3);
      if (type == "ball") {
        a.type = JointType::kBall;
      } else if (type == "hinge") {
        a.type = JointType::kHinge;
      } else {
        fail(r.where(), "column 'type': unknown joint type '" + std::string(type) +
                            "' (expected ball or hinge)");
      }
      a.angles_deg = Vec3(r.number(4), r.number(5), r.number(6));
      a.q_parent_child = read_quat(r, 7);
      if (r.has_column(14)) {
        a.solved_by = std::string(r.text(11));
        a.sd_deg = Vec3(r.number(12), r.number(13), r.number(14));
      }
      if (r.has_column(20) && !r.field_empty(15)) {
        a.has_rates = true;
        a.rate_deg_s = Vec3(r.number(15), r.number(16), r.number(17));
        a.rate_sd_deg_s = Vec3(r.number(18), r.number(19), r.number(20));
      }
      rows.push_back(std::move(a));
    }
    return rows;
  });
}

}  // namespace mocap
