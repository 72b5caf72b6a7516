// Design: fuzz entry points of the file formats: the PGM reader, every YAML/CSV loader
// of a recording and the blob file reader. The bytes become an in-memory file (fuzz_file) read
// through the public, path-based API, exactly as `mocap track` reads a recording. A loader must
// return a value or a one-line Error; accepted values are checked against the
// validation the loader promises (finite numbers, sizes in range, one-line messages).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "formats/blob_file.h"
#include "formats/joints_yaml.h"
#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"
#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {
namespace {

template <class T>
void check_error_is_one_line(const Expected<T>& r) {
  if (r) return;
  const std::string& m = r.error().message;
  fuzz_check(!m.empty(), "empty error message");
  if (m.find('\n') != std::string::npos) {
    std::fprintf(stderr, "message: %s\n", m.c_str());
    fuzz_check_failed("multi-line error message");
  }
}

bool finite3(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// The targets every model/joints input is checked against: three bodies as in the
// built-in scenario (names only matter to the loaders).
const TargetSet& fixed_targets() {
  static const TargetSet targets = [] {
    TargetSet t;
    for (const char* name : {"torso", "upper_arm", "lower_arm"}) {
      MarkerTarget m;
      m.name = name;
      m.markers_body = {Vec3(0, 0, 0), Vec3(60, 0, 0), Vec3(0, 45, 0), Vec3(0, 0, 30)};
      t.bodies.push_back(m);
    }
    return t;
  }();
  return targets;
}

void check_model(const Expected<JointModel>& r) {
  check_error_is_one_line(r);
  if (!r) return;
  for (const JointSpec& j : r->joints) {
    fuzz_check(finite3(j.center_parent) && finite3(j.center_child),
               "non-finite joint centre accepted");
    fuzz_check(finite3(j.axis_parent) && finite3(j.axis_child), "non-finite joint axis accepted");
  }
}

}  // namespace

int fuzz_pgm(const std::uint8_t* data, std::size_t size) {
  static Image reused;  // exercises the buffer-reuse path across inputs
  const char* path = fuzz_file(data, size);
  auto r = read_pgm(path, reused);
  check_error_is_one_line(r);
  if (r) {
    fuzz_check(reused.width() >= 1 && reused.width() <= kMaxImageSidePx, "width out of range");
    fuzz_check(reused.height() >= 1 && reused.height() <= kMaxImageSidePx, "height out of range");
    fuzz_check(
        reused.size_bytes() == static_cast<std::size_t>(reused.width()) *
                                   static_cast<std::size_t>(reused.height()) *
                                   static_cast<std::size_t>(bytes_per_pixel(reused.format())),
        "buffer size differs from the header");
    fuzz_check(reused.size_bytes() < size, "more pixels than input bytes");
    fuzz_check(reused.maxval() >= 1, "maxval 0 accepted");
  }
  Image fresh;
  auto e = read_pgm_expect(path, 8, 4, fresh);
  check_error_is_one_line(e);
  if (e)
    fuzz_check(fresh.width() == 8 && fresh.height() == 4, "read_pgm_expect accepted another size");
  return 0;
}

int fuzz_rig(const std::uint8_t* data, std::size_t size) {
  auto r = load_rig(fuzz_file(data, size));
  check_error_is_one_line(r);
  if (r) {
    fuzz_check(!r->cameras.empty(), "rig without cameras accepted");
    for (const CameraModel& c : r->cameras) {
      fuzz_check(c.width >= 1 && c.width <= kMaxImageSidePx && c.height >= 1 &&
                     c.height <= kMaxImageSidePx,
                 "camera size out of range");
      fuzz_check(std::isfinite(c.fx) && c.fx > 0 && std::isfinite(c.fy) && c.fy > 0,
                 "bad focal length accepted");
      fuzz_check(std::isfinite(c.cx) && std::isfinite(c.cy), "non-finite principal point accepted");
      fuzz_check(c.R_cam_world.allFinite() && c.t_cam_world.allFinite(),
                 "non-finite extrinsics accepted");
      fuzz_check(c.name.find('/') == std::string::npos && c.name != ".." && c.name != ".",
                 "camera name that is a path accepted");
      for (double k : c.distortion) fuzz_check(std::isfinite(k), "non-finite distortion accepted");
    }
  }
  return 0;
}

int fuzz_targets(const std::uint8_t* data, std::size_t size) {
  auto r = load_targets(fuzz_file(data, size));
  check_error_is_one_line(r);
  if (r) {
    for (const MarkerTarget& t : r->bodies) {
      for (const Vec3& m : t.markers_body) fuzz_check(finite3(m), "non-finite marker accepted");
    }
  }
  return 0;
}

int fuzz_joints(const std::uint8_t* data, std::size_t size) {
  check_model(load_joints(fuzz_file(data, size), fixed_targets()));
  return 0;
}

int fuzz_model(const std::uint8_t* data, std::size_t size) {
  check_model(load_model(fuzz_file(data, size), fixed_targets()));
  return 0;
}

int fuzz_frames_csv(const std::uint8_t* data, std::size_t size) {
  auto r = load_frames_csv(fuzz_file(data, size));
  check_error_is_one_line(r);
  if (r) {
    fuzz_check(!r->empty() && r->front().frame == 0, "frames do not start at 0");
    for (std::size_t i = 1; i < r->size(); ++i) {
      fuzz_check((*r)[i].frame > (*r)[i - 1].frame, "frames not strictly increasing");
    }
    for (const FrameEntry& e : *r) fuzz_check(e.timestamp_ns >= 0, "negative timestamp accepted");
  }
  return 0;
}

int fuzz_blob_file(const std::uint8_t* data, std::size_t size) {
  const char* path = fuzz_file(data, size);
  std::vector<std::string> warnings;
  auto r = BlobFileReader::open(path, warnings);
  check_error_is_one_line(r);
  for (const std::string& w : warnings)
    fuzz_check(!w.empty() && w.find('\n') == std::string::npos, "multi-line warning");
  if (!r) return 0;
  fuzz_check(r->info().max_blobs >= 1 && r->info().max_blobs <= kMaxBlobFileBlobs,
             "blob capacity out of range accepted");
  fuzz_check(r->info().record_bytes >= kBlobRecordBytes, "short blob record accepted");
  static detect::BlobList list(64);  // a capacity below the file's: the rest is refused
  static std::vector<std::uint8_t> scratch;
  std::uint64_t bytes = 0;
  for (std::size_t i = 0; i < r->chunks().size(); ++i) {
    const BlobFileReader::Chunk& c = r->chunks()[i];
    fuzz_check(c.count <= r->info().max_blobs, "chunk with more blobs than the capacity");
    fuzz_check(i == 0 || c.frame > r->chunks()[i - 1].frame, "frames not strictly increasing");
    fuzz_check(r->find(c.frame) == &c, "find() misses an indexed frame");
    bytes += kBlobChunkHeaderBytes + std::uint64_t{c.count} * r->info().record_bytes + 4;
    fuzz_check(bytes <= size, "chunks larger than the file");
    fuzz_check(r->load(c, list, scratch).ok(), "an indexed chunk does not load");
    fuzz_check(list.size() == std::min<std::size_t>(c.count, 64), "blob count differs");
  }
  return 0;
}

}  // namespace mocap::fuzz
