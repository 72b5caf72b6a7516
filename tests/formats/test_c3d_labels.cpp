// The C3D writer beyond 255 trajectories (docs/formats.md, "C3D"): a parameter dimension
// is one byte, so POINT:LABELS holds at most 255 labels and the C3D convention continues
// the list in POINT:LABELS2, LABELS3, ... (DESCRIPTIONS likewise), while POINT:USED (a
// signed 16-bit parameter) and the header's word 2 count every point. The reader below is
// written from the format description (header block, parameter records with their
// 16-bit signed offsets, float 3D data when POINT:SCALE < 0), not from the writer: a
// whole robot of 32 bodies x 16 markers (512 labels) reads back label for label and
// sample for sample; 255 and 256 labels split where the format says; the limits are
// one-line errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "formats/c3d_writer.h"

namespace mocap {
namespace {

struct Param {
  int type = 0;           // -1 char, 1 byte, 2 int16, 4 float
  std::vector<int> dims;  // first varies fastest
  std::vector<std::uint8_t> data;
  int next_offset = 0;  // the record's signed 16-bit offset word
};

struct C3d {
  std::vector<std::uint8_t> bytes;
  std::map<std::string, Param> params;  // "GROUP:NAME"
  int header_points = 0, first_frame = 0, last_frame = 0, data_start = 0;
  float scale = 0.0f;

  int i16(std::size_t at) const {
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(bytes[at] | (bytes[at + 1] << 8)));
  }
  int u16(std::size_t at) const { return bytes[at] | (bytes[at + 1] << 8); }
  float f32(std::size_t at) const {
    float v;
    std::memcpy(&v, &bytes[at], 4);  // the test host is little-endian like the file (Intel)
    return v;
  }
  int int_param(const std::string& key) const {
    const Param& p = params.at(key);
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(p.data[0] | (p.data[1] << 8)));
  }
  std::vector<std::string> strings(const std::string& key) const {
    const Param& p = params.at(key);
    std::vector<std::string> out;
    const int len = p.dims.at(0), n = p.dims.size() > 1 ? p.dims[1] : 1;
    for (int i = 0; i < n; ++i) {
      std::string s(p.data.begin() + i * len, p.data.begin() + (i + 1) * len);
      s.erase(s.find_last_not_of(' ') + 1);
      out.push_back(s);
    }
    return out;
  }
  // LABELS, then LABELS2, LABELS3, ... while they exist (the reader's side of the rule).
  std::vector<std::string> concatenated(const std::string& key) const {
    std::vector<std::string> all = strings(key);
    for (int part = 2; params.count(key + std::to_string(part)); ++part) {
      const auto more = strings(key + std::to_string(part));
      all.insert(all.end(), more.begin(), more.end());
    }
    return all;
  }
};

C3d read_c3d(const std::string& path) {
  C3d f;
  std::ifstream in(path, std::ios::binary);
  f.bytes.assign(std::istreambuf_iterator<char>(in), {});
  EXPECT_GE(f.bytes.size(), 1024u);
  EXPECT_EQ(f.bytes.size() % 512, 0u);
  EXPECT_EQ(f.bytes[1], 0x50);
  f.header_points = f.u16(2);
  f.first_frame = f.u16(6);
  f.last_frame = f.u16(8);
  f.scale = f.f32(12);
  f.data_start = f.u16(16);
  const std::size_t p0 = (static_cast<std::size_t>(f.bytes[0]) - 1) * 512;
  EXPECT_EQ(f.bytes[p0 + 3], 84);  // Intel
  const std::size_t end = p0 + 512 * static_cast<std::size_t>(f.bytes[p0 + 2]);
  std::map<int, std::string> groups;
  std::vector<std::pair<int, std::pair<std::string, Param>>> pending;
  std::size_t pos = p0 + 4;
  while (pos + 4 < end) {
    const int name_len = std::abs(static_cast<std::int8_t>(f.bytes[pos]));
    const int id = static_cast<std::int8_t>(f.bytes[pos + 1]);
    if (name_len == 0) break;
    const std::string name(f.bytes.begin() + static_cast<std::ptrdiff_t>(pos + 2),
                           f.bytes.begin() + static_cast<std::ptrdiff_t>(pos + 2 + name_len));
    const std::size_t offset_at = pos + 2 + name_len;
    const int next = f.i16(offset_at);
    if (id < 0) {
      groups[-id] = name;
    } else {
      Param p;
      p.next_offset = next;
      std::size_t q = offset_at + 2;
      p.type = static_cast<std::int8_t>(f.bytes[q]);
      const int ndims = f.bytes[q + 1];
      std::size_t count = 1;
      for (int d = 0; d < ndims; ++d) {
        p.dims.push_back(f.bytes[q + 2 + d]);
        count *= static_cast<std::size_t>(p.dims.back());
      }
      q += 2 + static_cast<std::size_t>(ndims);
      const std::size_t size = count * static_cast<std::size_t>(std::abs(p.type));
      p.data.assign(f.bytes.begin() + static_cast<std::ptrdiff_t>(q),
                    f.bytes.begin() + static_cast<std::ptrdiff_t>(q + size));
      pending.push_back({id, {name, p}});
    }
    if (next == 0) break;
    EXPECT_GT(next, 0) << name << ": a negative offset";
    pos = offset_at + static_cast<std::size_t>(next);
  }
  for (auto& [id, np] : pending) f.params[groups.at(id) + ":" + np.first] = np.second;
  return f;
}

TrajectoryLayout robot_layout(int bodies, int markers, std::int64_t frames) {
  TrajectoryLayout l;
  for (int b = 0; b < bodies; ++b)
    for (int m = 0; m < markers; ++m)
      l.labels.push_back("body" + std::to_string(b) + "_m" + std::to_string(m));
  l.rate_hz = 120.0;
  l.frame_count = frames;
  return l;
}

TrajectorySample sample_of(int frame, int point) {
  TrajectorySample s;
  s.valid = (frame + point) % 7 != 0;  // some invalid in every frame
  s.cameras = static_cast<std::uint8_t>(0x03 | (point % 4) << 2);
  s.X_mm = Vec3(point * 10.0 + 0.25, -point - 0.5 * frame, 1000.0 + frame);
  s.residual_mm = 0.1 * (1 + point % 20);
  return s;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("mocap_test_c3d_" + name)).string();
}

// Writes `layout` with sample_of() and reads it back.
C3d write_and_read(const TrajectoryLayout& layout, const std::string& name) {
  const std::string path = temp_path(name);
  auto w = C3dWriter::open(path, layout);
  EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.error().message);
  if (!w.ok()) return {};
  std::vector<TrajectorySample> frame(layout.labels.size());
  for (int f = 0; f < layout.frame_count; ++f) {
    for (std::size_t p = 0; p < frame.size(); ++p) frame[p] = sample_of(f, static_cast<int>(p));
    EXPECT_TRUE(w->write_frame(frame.data()));
  }
  EXPECT_TRUE(w->close().ok());
  C3d c = read_c3d(path);
  std::filesystem::remove(path);
  return c;
}

TEST(C3dLabels, WholeRobotOf512MarkersReadsBackThroughLabels2And3) {
  const TrajectoryLayout layout = robot_layout(32, 16, 3);
  const C3d c = write_and_read(layout, "512.c3d");
  ASSERT_FALSE(c.params.empty());
  EXPECT_EQ(c.header_points, 512);
  EXPECT_EQ(c.int_param("POINT:USED"), 512);
  // 255 + 255 + 2, in order, and nothing more.
  EXPECT_EQ(c.strings("POINT:LABELS").size(), 255u);
  EXPECT_EQ(c.strings("POINT:LABELS2").size(), 255u);
  EXPECT_EQ(c.strings("POINT:LABELS3").size(), 2u);
  EXPECT_EQ(c.params.count("POINT:LABELS4"), 0u);
  EXPECT_EQ(c.concatenated("POINT:LABELS"), layout.labels);
  EXPECT_EQ(c.concatenated("POINT:DESCRIPTIONS"), layout.labels);
  for (const auto& [key, p] : c.params) EXPECT_LE(p.next_offset, 32767) << key;
  EXPECT_EQ(c.data_start, c.int_param("POINT:DATA_START"));
  EXPECT_EQ(c.first_frame, 1);
  EXPECT_EQ(c.last_frame, 3);
  ASSERT_LT(c.scale, 0.0f);  // float data
  const std::size_t data = (static_cast<std::size_t>(c.data_start) - 1) * 512;
  ASSERT_GE(c.bytes.size(), data + 3 * 512 * 16);
  for (int f = 0; f < 3; ++f) {
    for (int p = 0; p < 512; ++p) {
      const std::size_t at = data + 16 * (static_cast<std::size_t>(f) * 512 + p);
      const TrajectorySample s = sample_of(f, p);
      const float word = c.f32(at + 12);
      if (!s.valid) {
        EXPECT_EQ(word, -1.0f) << f << " " << p;
        continue;
      }
      EXPECT_FLOAT_EQ(c.f32(at), static_cast<float>(s.X_mm.x())) << f << " " << layout.labels[p];
      EXPECT_FLOAT_EQ(c.f32(at + 4), static_cast<float>(s.X_mm.y()));
      EXPECT_FLOAT_EQ(c.f32(at + 8), static_cast<float>(s.X_mm.z()));
      const int w = static_cast<int>(word);
      EXPECT_EQ(w >> 8, s.cameras) << "camera mask";
      EXPECT_NEAR((w & 0xFF) * std::fabs(static_cast<double>(c.scale)), s.residual_mm, 0.05);
    }
  }
}

TEST(C3dLabels, SplitsExactlyAfter255) {
  const C3d a = write_and_read(robot_layout(1, 255, 1), "255.c3d");
  ASSERT_FALSE(a.params.empty());
  EXPECT_EQ(a.strings("POINT:LABELS").size(), 255u);
  EXPECT_EQ(a.params.count("POINT:LABELS2"), 0u);
  const C3d b = write_and_read(robot_layout(1, 256, 1), "256.c3d");
  ASSERT_FALSE(b.params.empty());
  EXPECT_EQ(b.int_param("POINT:USED"), 256);
  EXPECT_EQ(b.header_points, 256);
  ASSERT_EQ(b.strings("POINT:LABELS2").size(), 1u);
  EXPECT_EQ(b.strings("POINT:LABELS2")[0], "body0_m255");
  EXPECT_EQ(b.strings("POINT:DESCRIPTIONS2")[0], "body0_m255");
}

TEST(C3dLabels, FormatLimitsAreOneLineErrorsNamingTheFile) {
  const std::string path = temp_path("limits.c3d");
  TrajectoryLayout too_many = robot_layout(1, 1, 1);
  too_many.labels.assign(static_cast<std::size_t>(kC3dMaxPoints) + 1, "x");
  auto e = C3dWriter::open(path, too_many);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, path + ": POINT:LABELS: needs 1 to 32767 trajectories, got 32768");
  // 255 labels of 129 characters: one LABELS record would span more than its offset word.
  TrajectoryLayout wide = robot_layout(1, 1, 1);
  wide.labels.clear();
  for (int i = 0; i < 255; ++i)
    wide.labels.push_back(std::string(126, 'a') + std::to_string(100 + i));
  e = C3dWriter::open(path, wide);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message.rfind(path + ": POINT:LABELS: the labels are too long", 0), 0u)
      << e.error().message;
  EXPECT_EQ(e.error().message.find('\n'), std::string::npos);
  // 128 characters fit.
  for (std::string& s : wide.labels) s.erase(0, 1);
  EXPECT_TRUE(C3dWriter::open(path, wide).ok());
  TrajectoryLayout long_label = robot_layout(1, 1, 1);
  long_label.labels[0] = std::string(256, 'x');
  e = C3dWriter::open(path, long_label);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message.rfind(path + ": POINT:LABELS: label 'xxx", 0), 0u);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mocap
