// Design: the recording folder (see recording.h, docs/formats.md). open() validates
// rig.yaml, frames.csv and the presence of every camera's folder, so that replay only
// meets per-frame problems. load_frame builds the frame's path in a stack buffer and
// reads with the allocation-free PGM core: replaying into the same Image allocates
// nothing per frame. Blob recordings: see recording.h and blob_file.h.
#include "formats/recording.h"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>

#include "formats/blob_file.h"
#include "formats/csv_parse.h"
#include "formats/pgm_read.h"
#include "formats/rig_yaml.h"
#include "formats/text_io.h"

namespace mocap {

using namespace formats_detail;

Expected<std::vector<FrameEntry>> load_frames_csv(const std::string& path) {
  auto reader = CsvReader::open(path, "frame,timestamp_ns");
  if (!reader) return reader.error();
  return guard_fields<std::vector<FrameEntry>>(path, [&]() -> Expected<std::vector<FrameEntry>> {
    CsvReader& r = *reader;
    std::vector<FrameEntry> frames;
    while (r.next()) {
      FrameEntry e;
      e.frame = r.integer(0);
      e.timestamp_ns = r.integer(1);
      if (frames.empty() && e.frame != 0) {
        fail(r.where(), "the first frame is " + std::to_string(e.frame) + ", frames start at 0");
      }
      if (!frames.empty() && e.frame <= frames.back().frame) {
        fail(r.where(), "frame " + std::to_string(e.frame) + " does not follow frame " +
                            std::to_string(frames.back().frame) + " (must be strictly increasing)");
      }
      if (e.timestamp_ns < 0) {
        fail(r.where(), "negative timestamp_ns " + std::to_string(e.timestamp_ns));
      }
      frames.push_back(e);
    }
    if (frames.empty()) fail("", "no frames (only the header)");
    return frames;
  });
}

Expected<void> save_frames_csv(const std::string& path, const std::vector<FrameEntry>& frames) {
  std::string out = "frame,timestamp_ns\n";
  out.reserve(out.size() + frames.size() * 32);
  for (const FrameEntry& e : frames) {
    out += std::to_string(e.frame);
    out += ',';
    out += std::to_string(e.timestamp_ns);
    out += '\n';
  }
  return write_text_file(path, out);
}

std::string frame_file_path(const std::string& dir, const std::string& camera, std::int64_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "%06lld.pgm", static_cast<long long>(frame));
  return dir + "/" + camera + "/" + name;
}

Expected<Recording> Recording::open(const std::string& dir) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    return make_error(dir, "", "not a recording folder (no such directory)");
  }
  Recording rec;
  rec.dir_ = dir;
  auto rig = load_rig(dir + "/rig.yaml");
  if (!rig) return rig.error();
  rec.rig_ = std::move(*rig);
  auto frames = load_frames_csv(dir + "/frames.csv");
  if (!frames) return frames.error();
  rec.frames_ = std::move(*frames);
  // A blob recording: the blob file of any rig camera (a camera named "blobs" of an image
  // recording has PGMs there, no .blobs file).
  bool blobs = false;
  for (const CameraModel& cam : rec.rig_.cameras)
    blobs = blobs || ::stat(blob_file_path(dir, cam.name).c_str(), &st) == 0;
  if (blobs) {
    for (const CameraModel& cam : rec.rig_.cameras) {
      const std::string path = blob_file_path(dir, cam.name);
      if (::stat(path.c_str(), &st) != 0)
        return make_error(path, "",
                          "missing blob file of camera '" + cam.name +
                              "' named in rig.yaml (the recording has blobs/)");
      auto reader = BlobFileReader::open(path, rec.warnings_);
      if (!reader) return reader.error();
      const BlobFileInfo& info = reader->info();
      if (info.camera != cam.name)
        return make_error(path, "header",
                          "camera '" + info.camera + "', expected '" + cam.name + "' (rig.yaml)");
      if (info.width != cam.width || info.height != cam.height)
        return make_error(path, "header",
                          "image size " + std::to_string(info.width) + "x" +
                              std::to_string(info.height) + ", rig.yaml says " +
                              std::to_string(cam.width) + "x" + std::to_string(cam.height));
      rec.blob_files_.push_back(std::make_shared<const BlobFileReader>(std::move(*reader)));
    }
    return rec;
  }
  for (const CameraModel& cam : rec.rig_.cameras) {
    const std::string folder = dir + "/" + cam.name;
    if (::stat(folder.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
      return make_error(folder, "",
                        "missing folder of camera '" + cam.name + "' named in rig.yaml");
    }
  }
  return rec;
}

std::uint32_t Recording::max_blobs() const noexcept {
  std::uint32_t m = 0;
  for (const auto& f : blob_files_) m = std::max(m, f->info().max_blobs);
  return m;
}

std::string Recording::blob_file_path(const std::string& dir, const std::string& camera) {
  return dir + "/blobs/" + camera + ".blobs";
}

Expected<FrameLoad> Recording::load_blobs(int camera_index, std::int64_t frame,
                                          detect::BlobList& out,
                                          std::vector<std::uint8_t>& scratch) const {
  if (camera_index < 0 || static_cast<std::size_t>(camera_index) >= blob_files_.size())
    return make_error(dir_, "",
                      blob_files_.empty()
                          ? "not a blob recording (no blobs/ folder)"
                          : "camera index " + std::to_string(camera_index) + " out of range");
  const BlobFileReader& file = *blob_files_[static_cast<std::size_t>(camera_index)];
  const BlobFileReader::Chunk* chunk = file.find(frame);
  if (chunk == nullptr) {
    out.clear();
    return FrameLoad::kMissing;
  }
  if (auto r = file.load(*chunk, out, scratch); !r) return r.error();
  return FrameLoad::kOk;
}

Expected<FrameLoad> Recording::load_frame(int camera_index, std::int64_t frame, Image& out) const {
  if (camera_index < 0 || static_cast<std::size_t>(camera_index) >= rig_.cameras.size()) {
    return make_error(dir_, "",
                      "camera index " + std::to_string(camera_index) + " out of range (" +
                          std::to_string(rig_.cameras.size()) + " cameras)");
  }
  if (frame < 0 || frame > 999999999) {
    return make_error(dir_, "", "frame number " + std::to_string(frame) + " out of range");
  }
  const CameraModel& cam = rig_.cameras[static_cast<std::size_t>(camera_index)];
  char path[4096];
  const int len = std::snprintf(path, sizeof path, "%s/%s/%06lld.pgm", dir_.c_str(),
                                cam.name.c_str(), static_cast<long long>(frame));
  if (len < 0 || static_cast<std::size_t>(len) >= sizeof path) {
    return make_error(dir_, "", "frame path too long");
  }
  bool missing = false;
  if (auto r = read_pgm_path(path, cam.width, cam.height, out, &missing); !r) return r.error();
  return missing ? FrameLoad::kMissing : FrameLoad::kOk;
}

FrameSetLoader::FrameSetLoader(const Recording& rec)
    : rec_(&rec),
      images_(rec.rig().cameras.size()),
      views_(rec.rig().cameras.size()),
      present_(rec.rig().cameras.size(), nullptr) {}

FrameSetLoader::Result FrameSetLoader::load(std::int64_t frame) {
  Result r;
  for (std::size_t c = 0; c < images_.size(); ++c) {
    present_[c] = nullptr;
    auto loaded = rec_->load_frame(static_cast<int>(c), frame, images_[c]);
    if (!loaded) {
      if (r.damaged++ == 0) r.problem = loaded.error().message;
    } else if (*loaded == FrameLoad::kMissing) {
      ++r.missing;
    } else {
      views_[c] = images_[c].view();
      present_[c] = &views_[c];
    }
  }
  return r;
}

}  // namespace mocap
