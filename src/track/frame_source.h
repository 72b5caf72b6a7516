// Design: the one seam where the offline commands (`mocap track`, `calibrate`, `discover`)
// obtain a frame's blob lists from a recording, whatever the recording holds:
//   - an image recording: each camera's PGM is loaded (FrameSetLoader) and detected with
//     the FrameProcessor's detectors (on two threads with ParallelDetect, as live);
//   - a blob recording (blobs/<camera>.blobs, formats/blob_file.h): each camera's blob
//     list and image levels are read from its file; nothing is detected.
// Both fill FrameOutput::blobs and camera_present exactly as FrameProcessor::process
// does, so the stages after detection compute the same result from either source. A
// camera whose frame is absent (no PGM, no chunk) is missing (a dropped frame); a damaged
// one is reported (problem, one line naming the file) and treated as missing.
// times.load is the file reading (the PGMs, or the blob lists), times.detect the detection
// (0 for blob recordings); times.frame, the in-memory work, leaves the reading out (the
// spec's stats.json: "file reading excluded").
// Offline code: allocates at construction and while buffers grow, not per frame after.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "formats/recording.h"
#include "track/detect_workers.h"
#include "track/frame_processor.h"

namespace mocap {

class FrameSource {
 public:
  struct Result {
    int present = 0;      // cameras with a frame
    int missing = 0;      // cameras without one (a dropped frame)
    int damaged = 0;      // cameras whose file is malformed (see `problem`)
    std::string problem;  // the first damaged camera's one-line error, empty if none
  };
  // rec and proc must outlive this object. detect_threads >= 2 detects images on two
  // threads (a worker is started; unused for blob recordings).
  FrameSource(const Recording& rec, FrameProcessor& proc, int detect_threads);
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;

  bool from_blobs() const noexcept { return rec_.has_blobs(); }
  // Stage 1 of frame `frame`: out.blobs, out.camera_present, out.times.load and .detect.
  Result load(std::int64_t frame, FrameOutput& out);
  // load() and the stages after it (FrameProcessor::process_blobs), as process() does.
  Result process(const FrameEntry& entry, FrameOutput& out);

 private:
  const Recording& rec_;
  FrameProcessor& proc_;
  std::optional<FrameSetLoader> images_;
  std::optional<ParallelDetect> parallel_;
  std::vector<std::vector<std::uint8_t>> scratch_;  // per camera (blob recordings)
};

}  // namespace mocap
