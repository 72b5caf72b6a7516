// Tests of points.csv, poses.csv and angles.csv: exact headers, fixed precision,
// qw >= 0, round trips (values within the written precision; text identical after a
// second write) and reader errors naming the line and column.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "formats/csv_outputs.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

class CsvOutputsTest : public ::testing::Test {
 protected:
  test::TempDir dir{"csv_outputs"};
};

std::vector<PointRow> sample_points() {
  std::vector<PointRow> rows;
  for (int i = 0; i < 5; ++i) {
    PointRow r;
    r.frame = i / 2;
    r.X_world = Vec3(100.0 / 3.0 * i, -1234.5678912 + i, 1e-7 * i);
    r.reproj_px = 0.123456789 * i;
    rows.push_back(r);
  }
  return rows;
}

std::vector<PoseRow> sample_poses() {
  std::vector<PoseRow> rows;
  for (int i = 0; i < 4; ++i) {
    PoseRow r;
    r.frame = i;
    r.timestamp_ns = 1'000'000'000'000LL + i * 3'333'333;
    r.body = i % 2 ? "torso" : "upper_arm";
    r.q_world_body = Quat(Eigen::AngleAxisd(0.3 + i, Vec3(1, 2, 3).normalized()));
    r.t_world_body = Vec3(1.0 / 7.0, 2000.25, -3.5 * i);
    r.markers = 3 + i;
    r.rms_mm = 0.05 * i;
    r.has_velocity = i != 0;  // the extension columns empty in the first row
    if (r.has_velocity) {
      r.v_world_mm_s = Vec3(12.5, -1000.25, 0.0625 * i);
      r.w_world_deg_s = Vec3(-90.5, 0.125, 360.0);
      r.v_sd_mm_s = Vec3(0.5, 0.75, 1.0);
      r.w_sd_deg_s = Vec3(0.25, 0.125, 2.0);
    }
    rows.push_back(r);
  }
  return rows;
}

std::vector<AngleRow> sample_angles() {
  std::vector<AngleRow> rows;
  for (int i = 0; i < 4; ++i) {
    AngleRow r;
    r.frame = i;
    r.timestamp_ns = 5 + i;
    r.joint = i % 2 ? "elbow" : "shoulder";
    r.type = i % 2 ? JointType::kHinge : JointType::kBall;
    r.angles_deg = i % 2 ? Vec3(12.3456789, 0, 0) : Vec3(-170.1, 45.000001, 3.3);
    r.q_parent_child = Quat(Eigen::AngleAxisd(2.5 * i, Vec3(0, 0.6, 0.8)));
    r.solved_by = i == 0 ? "" : (i % 2 ? "chain" : "poses");
    r.sd_deg = Vec3(0.25, 0.5, 0.125) * (i % 2 ? 1.0 : 0.5);
    r.has_rates = i >= 2;  // rows 0 and 1: the filter is warming up (empty columns)
    if (r.has_rates) {
      r.rate_deg_s = Vec3(-123.4567, 8.25, 0.0) * (i % 2 ? 1.0 : 2.0);
      r.rate_sd_deg_s = Vec3(1.5, 2.25, 3.125);
    }
    rows.push_back(r);
  }
  return rows;
}

TEST_F(CsvOutputsTest, PointsRoundTrip) {
  const std::string path = dir.file("points.csv");
  const auto rows = sample_points();
  {
    auto f = open_points_csv(path);
    ASSERT_TRUE(f.ok()) << f.error().message;
    for (const auto& r : rows) write_row(*f, r);
    ASSERT_TRUE(f->close().ok());
  }
  const std::string text = test::read_file(path);
  EXPECT_THAT(text,
              StartsWith("frame,x,y,z,reproj_px\n0,0.000000,-1234.567891,0.000000,0.000000\n"));
  auto back = read_points_csv(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ((*back)[i].frame, rows[i].frame);
    EXPECT_NEAR(((*back)[i].X_world - rows[i].X_world).cwiseAbs().maxCoeff(), 0.0, 5e-7);
    EXPECT_NEAR((*back)[i].reproj_px, rows[i].reproj_px, 5e-7);
  }
  // Writing what was read gives the same bytes.
  auto f = open_points_csv(path);
  ASSERT_TRUE(f.ok());
  for (const auto& r : *back) write_row(*f, r);
  ASSERT_TRUE(f->close().ok());
  EXPECT_EQ(test::read_file(path), text);
}

TEST_F(CsvOutputsTest, PosesRoundTripWithQwPositive) {
  const std::string path = dir.file("poses.csv");
  const auto rows = sample_poses();
  {
    auto f = open_poses_csv(path);
    ASSERT_TRUE(f.ok());
    for (const auto& r : rows) write_row(*f, r);
    ASSERT_TRUE(f->close().ok());
  }
  const std::string text = test::read_file(path);
  EXPECT_THAT(text, StartsWith("frame,timestamp_ns,body,qw,qx,qy,qz,tx,ty,tz,markers,rms_mm,"
                               "vx,vy,vz,wx,wy,wz,sd_vx,sd_vy,sd_vz,sd_wx,sd_wy,sd_wz\n0,"
                               "1000000000000,upper_arm,"));
  auto back = read_poses_csv(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const PoseRow& b = (*back)[i];
    EXPECT_EQ(b.frame, rows[i].frame);
    EXPECT_EQ(b.timestamp_ns, rows[i].timestamp_ns);
    EXPECT_EQ(b.body, rows[i].body);
    EXPECT_GE(b.q_world_body.w(), 0.0);
    EXPECT_NEAR(b.q_world_body.angularDistance(rows[i].q_world_body), 0.0, 1e-8);
    EXPECT_NEAR((b.t_world_body - rows[i].t_world_body).cwiseAbs().maxCoeff(), 0.0, 5e-7);
    EXPECT_EQ(b.markers, rows[i].markers);
    EXPECT_NEAR(b.rms_mm, rows[i].rms_mm, 5e-7);
    EXPECT_EQ(b.has_velocity, rows[i].has_velocity);
    EXPECT_EQ(b.v_world_mm_s, rows[i].v_world_mm_s);  // exact in 4 decimals
    EXPECT_EQ(b.w_world_deg_s, rows[i].w_world_deg_s);
    EXPECT_EQ(b.v_sd_mm_s, rows[i].v_sd_mm_s);
    EXPECT_EQ(b.w_sd_deg_s, rows[i].w_sd_deg_s);
  }
  auto f = open_poses_csv(path);
  ASSERT_TRUE(f.ok());
  for (const auto& r : *back) write_row(*f, r);
  ASSERT_TRUE(f->close().ok());
  EXPECT_EQ(test::read_file(path), text);
}

TEST_F(CsvOutputsTest, AnglesRoundTrip) {
  const std::string path = dir.file("angles.csv");
  const auto rows = sample_angles();
  {
    auto f = open_angles_csv(path);
    ASSERT_TRUE(f.ok());
    for (const auto& r : rows) write_row(*f, r);
    ASSERT_TRUE(f->close().ok());
  }
  const std::string text = test::read_file(path);
  EXPECT_THAT(text, HasSubstr("frame,timestamp_ns,joint,type,a0,a1,a2,qw,qx,qy,qz,solved_by,sd_a0,"
                              "sd_a1,sd_a2,da0,da1,da2,sd_da0,sd_da1,sd_da2\n0,5,shoulder,ball,"
                              "-170.100000,45.000001,3.300000,"));
  // The extension columns: how each angle was solved, its standard deviations and (2027-01)
  // its rates with theirs, empty while unknown.
  EXPECT_THAT(text, HasSubstr(",chain,0.250000,0.500000,0.125000,,,,,,\n"));
  EXPECT_THAT(text, HasSubstr(",-123.4567,8.2500,0.0000,1.5000,2.2500,3.1250\n"));
  EXPECT_THAT(text, HasSubstr("\n1,6,elbow,hinge,12.345679,0.000000,0.000000,"));
  auto back = read_angles_csv(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const AngleRow& b = (*back)[i];
    EXPECT_EQ(b.frame, rows[i].frame);
    EXPECT_EQ(b.timestamp_ns, rows[i].timestamp_ns);
    EXPECT_EQ(b.joint, rows[i].joint);
    EXPECT_EQ(b.solved_by, rows[i].solved_by.empty() ? "none" : rows[i].solved_by);
    EXPECT_NEAR((b.sd_deg - rows[i].sd_deg).norm(), 0.0, 1e-6);
    EXPECT_EQ(b.has_rates, rows[i].has_rates);
    EXPECT_NEAR((b.rate_deg_s - rows[i].rate_deg_s).norm(), 0.0, 1e-4);
    EXPECT_NEAR((b.rate_sd_deg_s - rows[i].rate_sd_deg_s).norm(), 0.0, 1e-4);
    EXPECT_EQ(b.type, rows[i].type);
    EXPECT_NEAR((b.angles_deg - rows[i].angles_deg).cwiseAbs().maxCoeff(), 0.0, 5e-7);
    EXPECT_GE(b.q_parent_child.w(), 0.0);
    EXPECT_NEAR(b.q_parent_child.angularDistance(rows[i].q_parent_child), 0.0, 1e-8);
  }
  auto f = open_angles_csv(path);
  ASSERT_TRUE(f.ok());
  for (const auto& r : *back) write_row(*f, r);
  ASSERT_TRUE(f->close().ok());
  EXPECT_EQ(test::read_file(path), text);
}

TEST_F(CsvOutputsTest, OpenInMissingFolderFails) {
  auto f = open_points_csv(dir.file("no/such/points.csv"));
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().message,
            dir.file("no/such/points.csv") + ": cannot write: No such file or directory");
}

TEST_F(CsvOutputsTest, ReaderErrorsNameLineAndColumn) {
  const std::string path = dir.file("poses.csv");
  test::write_file(path,
                   "frame,timestamp_ns,body,qw,qx,qy,qz,tx,ty,tz,markers,rms_mm\n"
                   "0,1,torso,1,0,0,0,1,2,3,4,0.1\n"
                   "1,2,torso,1,0,0,0,1,oops,3,4,0.1\n");
  auto r = read_poses_csv(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, path + ": line 3: column 'ty': expected a number, got 'oops'");

  test::write_file(path, "frame,x,y,z\n");
  auto p = read_points_csv(path);
  ASSERT_FALSE(p.ok());
  EXPECT_THAT(
      p.error().message,
      HasSubstr("line 1: header 'frame,x,y,z' does not start with 'frame,x,y,z,reproj_px'"));

  test::write_file(
      path, "frame,timestamp_ns,joint,type,a0,a1,a2,qw,qx,qy,qz\n0,1,knee,slider,0,0,0,1,0,0,0\n");
  auto a = read_angles_csv(path);
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.error().message, HasSubstr("line 2: column 'type': unknown joint type 'slider'"));

  test::write_file(path, "frame,x,y,z,reproj_px\n0,1,nan,3,0\n");
  auto n = read_points_csv(path);
  ASSERT_FALSE(n.ok());
  EXPECT_THAT(n.error().message, HasSubstr("line 2: column 'y': not a finite number: 'nan'"));
}

TEST_F(CsvOutputsTest, HeaderOnlyIsAnEmptyTable) {
  const std::string path = dir.file("points.csv");
  test::write_file(path, "frame,x,y,z,reproj_px\n");
  auto r = read_points_csv(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(r->empty());
}

}  // namespace
}  // namespace mocap
