// label_markers() (the one list behind markers.csv, C3D, TRC and the live sinks), the
// frame rate of the exports, and the C3D/TRC writers' limits and write errors: every
// failure is one line naming the file; the per-frame calls allocate nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "formats/c3d_writer.h"
#include "formats/fixed_text.h"
#include "formats/trc_writer.h"
#include "tests/support/alloc_counter.h"
#include "track/labelled_markers.h"
#include "track/trajectory_export.h"

namespace mocap {
namespace {

TargetSet one_body() {
  TargetSet t;
  t.bodies.push_back({"arm", {Vec3(0, 0, 0), Vec3(100, 0, 0), Vec3(0, 50, 0), Vec3(0, 0, 30)}});
  return t;
}

FrameOutput frame_with_body() {
  FrameOutput out;
  out.points.set_capacity(8);
  Point3 p;
  p.blob_index = {3, 4, -1, -1};
  p.X_world = Vec3(10.0, 50.5, 0.0);  // model marker 2 posed at (10, 50, 0): residual 0.5
  out.points.push_back(p);
  p.blob_index = {1, -1, 2, -1};
  p.X_world = Vec3(110.0, 0.0, 0.0);  // marker 1 exactly
  out.points.push_back(p);
  out.poses.count = 1;
  BodyPose& b = out.poses.bodies[0];
  b.found = true;
  b.T_world_body = Iso3::Identity();
  b.T_world_body.translation() = Vec3(10, 0, 0);
  b.point_index_of_marker.fill(-1);
  b.point_index_of_marker[1] = 1;
  b.point_index_of_marker[2] = 0;
  b.point_index_of_marker[3] = 7;  // outside the frame's points: skipped
  return out;
}

TEST(LabelMarkers, OrderedByMarkerWithResidualAndCameraMask) {
  const TargetSet targets = one_body();
  const FrameOutput out = frame_with_body();
  auto labelled = std::make_unique<LabelledMarkers>();
  test::AllocationScope scope;
  ASSERT_EQ(label_markers(out, targets, *labelled), 2);
  EXPECT_EQ(scope.count(), 0u);
  const LabelledMarker& a = labelled->items[0];
  EXPECT_EQ(a.body, 0);
  EXPECT_EQ(a.marker, 1);
  EXPECT_EQ(a.point, 1);
  EXPECT_EQ(a.cameras, 0b101);
  EXPECT_NEAR(a.residual_mm, 0.0, 1e-12);
  const LabelledMarker& b = labelled->items[1];
  EXPECT_EQ(b.marker, 2);
  EXPECT_EQ(b.cameras, 0b11);
  EXPECT_NEAR(b.residual_mm, 0.5, 1e-12);
  EXPECT_EQ(b.X_world_mm, Vec3(10.0, 50.5, 0.0));
}

TEST(LabelMarkers, BodyNotFoundGivesNoMarkers) {
  const TargetSet targets = one_body();
  FrameOutput out = frame_with_body();
  out.poses.bodies[0].found = false;
  auto labelled = std::make_unique<LabelledMarkers>();
  EXPECT_EQ(label_markers(out, targets, *labelled), 0);
}

TEST(FrameRate, MedianStepPerFrameNumberAndErrors) {
  // 100 fps with one dropped frame number and one late timestamp: the median wins.
  const std::vector<FrameEntry> f{
      {0, 0}, {1, 10'000'000}, {3, 30'000'000}, {4, 41'000'000}, {5, 50'000'000}};
  auto r = frame_rate_hz(f, "rec/frames.csv");
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(*r, 100.0, 1e-9);
  auto one = frame_rate_hz(std::vector<FrameEntry>{FrameEntry{0, 0}}, "rec/frames.csv");
  ASSERT_FALSE(one.ok());
  EXPECT_EQ(one.error().message.rfind("rec/frames.csv: ", 0), 0u) << one.error().message;
  auto back =
      frame_rate_hz(std::vector<FrameEntry>{FrameEntry{0, 5}, FrameEntry{1, 5}}, "rec/frames.csv");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("frame 1"), std::string::npos) << back.error().message;
}

TEST(FixedText, SameDigitsAsPrintf) {
  // The text writers format with to_chars; markers.csv and TRC must read as "%.6f" did.
  std::vector<double> values{0.0, -0.0, 0.0078125, -0.0078125, 2.5e-7,        -4e-7,
                             1e9, -1e9, 123.4565,  0.1234565,  999999.9999995};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5000.0, 5000.0);
  for (int i = 0; i < 20000; ++i) values.push_back(u(rng));
  for (double v : values) {
    char expected[64], got[64];
    std::snprintf(expected, sizeof expected, "%.6f", v);
    char* end = formats_detail::put_fixed(got, got + sizeof got - 1, v, 6);
    ASSERT_NE(end, nullptr);
    *end = '\0';
    ASSERT_STREQ(got, expected) << v;
  }
  char small[4];
  EXPECT_EQ(formats_detail::put_fixed(small, small + sizeof small, 1234.5, 6), nullptr);
}

TrajectoryLayout layout(std::int64_t frames, std::int64_t first = 1) {
  TrajectoryLayout l;
  l.labels = {"arm_m0", "arm_m1"};
  l.rate_hz = 100.0;
  l.frame_count = frames;
  l.first_frame = first;
  return l;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("mocap_test_" + name)).string();
}

TEST(C3dWriter, LimitsAreOneLineErrorsNamingTheFile) {
  const std::string path = temp_path("limits.c3d");
  auto too_long = C3dWriter::open(path, layout(600, 65000));
  ASSERT_FALSE(too_long.ok());
  EXPECT_EQ(too_long.error().message.rfind(path + ": POINT:FRAMES: frames 65000..65599", 0), 0u)
      << too_long.error().message;
  TrajectoryLayout none = layout(10);
  none.labels.clear();
  auto empty = C3dWriter::open(path, none);
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().message.find("POINT:LABELS"), std::string::npos);
  TrajectoryLayout many = layout(10);
  many.labels.assign(32768, "x");  // POINT:USED is signed 16-bit (more than 255: LABELS2...)
  EXPECT_FALSE(C3dWriter::open(path, many).ok());
  auto dir = C3dWriter::open("/nonexistent_dir/x.c3d", layout(10));
  ASSERT_FALSE(dir.ok());
  EXPECT_EQ(dir.error().message.rfind("/nonexistent_dir/x.c3d: cannot write: ", 0), 0u);
  EXPECT_TRUE(C3dWriter::open(path, layout(65535)).ok());  // the largest that fits
  std::filesystem::remove(path);
}

TEST(C3dWriter, FullDiskAndShortRecordingAreReportedAtClose) {
  const TrajectorySample samples[2] = {};
  if (std::filesystem::exists("/dev/full")) {
    auto full = C3dWriter::open("/dev/full", layout(400));  // buffered: fails on a later write
    ASSERT_TRUE(full.ok());
    for (int i = 0; i < 400; ++i) full->write_frame(samples);
    auto r = full->close();
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message, "/dev/full: cannot write: No space left on device");
  }
  const std::string path = temp_path("short.c3d");
  auto w = C3dWriter::open(path, layout(3));
  ASSERT_TRUE(w.ok());
  EXPECT_TRUE(w->write_frame(samples));
  auto r = w->close();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, path + ": POINT:FRAMES: wrote 1 frames, declared 3");
  EXPECT_EQ(std::filesystem::file_size(path) % 512, 0u);
  std::filesystem::remove(path);
}

TEST(Writers, PerFrameCallsAllocateNothing) {
  const std::string c3d_path = temp_path("alloc.c3d"), trc_path = temp_path("alloc.trc");
  auto c3d = C3dWriter::open(c3d_path, layout(50));
  auto trc = TrcWriter::open(trc_path, layout(50));
  ASSERT_TRUE(c3d.ok() && trc.ok());
  TrajectorySample s[2];
  s[1].valid = true;
  s[1].X_mm = Vec3(1e12, -3.5, 2.25);  // absurd coordinate: still a bounded TRC cell
  s[1].residual_mm = 1e9;
  ASSERT_TRUE(c3d->write_frame(s) && trc->write_frame(1, 0.0, s));  // first write sets up stdio
  test::AllocationScope scope;
  for (int i = 1; i < 50; ++i) {
    EXPECT_TRUE(c3d->write_frame(s));
    EXPECT_TRUE(trc->write_frame(i + 1, i * 0.01, s));
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_TRUE(c3d->close().ok());
  EXPECT_TRUE(trc->close().ok());
  std::filesystem::remove(c3d_path);
  std::filesystem::remove(trc_path);
}

TEST(TrcWriter, FullDiskAndBadLabelAreOneLine) {
  if (std::filesystem::exists("/dev/full")) {
    auto full = TrcWriter::open("/dev/full", layout(2));
    if (full.ok()) {  // the header may already fail at open (unbuffered path): also fine
      const TrajectorySample samples[2] = {};
      full->write_frame(1, 0.0, samples);
      full->write_frame(2, 0.01, samples);
      auto r = full->close();
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.error().message.rfind("/dev/full: cannot write: ", 0), 0u);
    } else {
      EXPECT_EQ(full.error().message.rfind("/dev/full: ", 0), 0u);
    }
  }
  TrajectoryLayout bad = layout(2);
  bad.labels[0] = "arm\tm0";
  auto r = TrcWriter::open(temp_path("bad.trc"), bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("contains a tab"), std::string::npos);
}

}  // namespace
}  // namespace mocap
