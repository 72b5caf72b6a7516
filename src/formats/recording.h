// Design: a recording folder as the spec defines it: rig.yaml, frames.csv
// ("frame,timestamp_ns", frames from 0, strictly increasing) and one folder of
// six-digit-numbered PGM files per camera, named as in rig.yaml. A frame missing from
// a camera is not an error: load_frame reports it as FrameLoad::kMissing.
// Blob recordings (docs/formats.md, "Blob recordings"): `blobs/<camera>.blobs` per camera
// in place of the image folders; open() recognises them (a `blobs/` folder with the file of
// a rig camera), and they take precedence: the camera folders, if any, then hold only the
// images kept for inspection (`mocap record --blobs --keep-images N`). open() scans every
// blob file once (blob_file.h) and keeps the problems that leave it readable in
// warnings(); load_blobs() reads one camera's blob list of a frame, kMissing where the
// file has no chunk of that frame (the camera dropped it).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/image.h"
#include "detect/blob.h"

namespace mocap {

struct FrameEntry {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
};

Expected<std::vector<FrameEntry>> load_frames_csv(const std::string& path);
Expected<void> save_frames_csv(const std::string& path, const std::vector<FrameEntry>& frames);

// "<dir>/<camera>/<frame, six digits>.pgm"
std::string frame_file_path(const std::string& dir, const std::string& camera, std::int64_t frame);

enum class FrameLoad { kOk, kMissing };

class Recording;
class BlobFileReader;

// One frame of every camera of a recording, loaded into reused images: views() has one
// entry per camera, null where that camera's frame is missing or damaged. Allocates on
// the first frame (and when a frame's size or format changes), not after.
class FrameSetLoader {
 public:
  struct Result {
    int missing = 0;      // cameras whose file does not exist (a dropped frame)
    int damaged = 0;      // cameras whose file exists but is malformed (see `problem`)
    std::string problem;  // the first damaged file's one-line error, empty if none
  };
  explicit FrameSetLoader(const Recording& rec);
  Result load(std::int64_t frame);
  std::span<const ImageView* const> views() const noexcept { return present_; }

 private:
  const Recording* rec_;
  std::vector<Image> images_;
  std::vector<ImageView> views_;
  std::vector<const ImageView*> present_;
};

class Recording {
 public:
  // Loads and validates rig.yaml and frames.csv of the folder.
  static Expected<Recording> open(const std::string& dir);

  const std::string& dir() const noexcept { return dir_; }
  const Rig& rig() const noexcept { return rig_; }
  const std::vector<FrameEntry>& frames() const noexcept { return frames_; }
  // A blob recording: blob lists per camera instead of images (see the top).
  bool has_blobs() const noexcept { return !blob_files_.empty(); }
  // Problems of the blob files that leave them readable (torn tail, damaged chunks), one
  // line each naming the file and the byte offset.
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }
  // The largest blob capacity of the blob files' headers (0: an image recording).
  std::uint32_t max_blobs() const noexcept;
  // "<dir>/blobs/<camera>.blobs"
  static std::string blob_file_path(const std::string& dir, const std::string& camera);

  // Blob recordings: camera `camera_index`'s blob list of `frame` into `out` (its levels
  // too). kMissing when the file has no chunk of the frame; an Error naming the file when
  // the recording has no blobs or the chunk changed since open(). Thread-safe between
  // callers with their own `out` and `scratch`; allocation-free once `scratch` has grown
  // to the file's largest chunk.
  Expected<FrameLoad> load_blobs(int camera_index, std::int64_t frame, detect::BlobList& out,
                                 std::vector<std::uint8_t>& scratch) const;

  // Reads camera `camera_index`'s image of `frame` into `out` (reusing its buffer).
  // kMissing when the file does not exist (out is left untouched); an Error naming the
  // file when it exists but is malformed or its size differs from the rig's. Allocates
  // nothing when `out` already has the rig's size and the frame's pixel format; safe to
  // call from several threads at once (each with its own Image).
  Expected<FrameLoad> load_frame(int camera_index, std::int64_t frame, Image& out) const;

 private:
  std::string dir_;
  Rig rig_;
  std::vector<FrameEntry> frames_;
  std::vector<std::shared_ptr<const BlobFileReader>> blob_files_;  // per camera, or none
  std::vector<std::string> warnings_;
};

}  // namespace mocap
