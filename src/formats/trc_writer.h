// Design: a streaming writer of OpenSim's TRC marker file (tab-separated text): line 1
// `PathFileType 4 (X/Y/Z) NAME`, line 2 the header keys (DataRate, CameraRate, NumFrames,
// NumMarkers, Units, OrigDataRate, OrigDataStartFrame, OrigNumFrames), line 3 their
// values, line 4 `Frame# Time` and each marker label over its three columns, line 5 the
// column names X1 Y1 Z1 X2 ..., a blank line, then one line per frame: frame number,
// time in seconds, X Y Z in mm per marker. A marker not seen in a frame has three empty
// cells (read as NaN by OpenSim). The per-frame line is formatted into a buffer sized at
// open; write failures are reported by close() naming the file.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "formats/export_file.h"
#include "formats/trajectory_export.h"

namespace mocap {

class TrcWriter {
 public:
  static Expected<TrcWriter> open(const std::string& path, const TrajectoryLayout& layout);
  TrcWriter(TrcWriter&&) noexcept = default;
  TrcWriter& operator=(TrcWriter&&) noexcept = default;
  ~TrcWriter() = default;

  // One frame: its number (Frame#), its time in seconds and layout.labels.size() samples.
  bool write_frame(std::int64_t frame_number, double time_s,
                   const TrajectorySample* samples) noexcept;
  Expected<void> close();

 private:
  explicit TrcWriter(formats_detail::ExportFile file) : file_(std::move(file)) {}
  formats_detail::ExportFile file_;
  std::vector<char> line_;  // one frame's line, sized at open
  std::size_t markers_ = 0;
  std::int64_t frames_declared_ = 0;
  std::int64_t frames_written_ = 0;
};

}  // namespace mocap
