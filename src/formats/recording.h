// Design: a recording folder as the spec defines it: rig.yaml, frames.csv
// ("frame,timestamp_ns", frames from 0, strictly increasing) and one folder of
// six-digit-numbered PGM files per camera, named as in rig.yaml. A frame missing from
// a camera is not an error: load_frame reports it as FrameLoad::kMissing.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/image.h"

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
};

}  // namespace mocap
