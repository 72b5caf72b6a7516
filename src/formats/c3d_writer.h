// Design: a streaming C3D writer for labelled marker trajectories, written from the
// C3D format description (c3d.org user guide): a 512-byte header block, a parameter
// section (Intel processor type 84, groups POINT, ANALOG, TRIAL) and a 3D data section of
// floating-point samples (POINT:SCALE < 0): per frame and point the four float words
// X, Y, Z (mm) and the residual word. A valid sample's residual word is the integer
// (camera mask << 8 | residual / |SCALE|, at least 1) stored as a float; a marker not
// seen in a frame is invalid: X = Y = Z = 0 and residual word -1. No analog data.
// Labels: POINT:LABELS holds the first 255 (a parameter dimension is one byte), the next
// 255 go to POINT:LABELS2, then LABELS3, ... (the C3D convention for more than 255
// points; DESCRIPTIONS likewise); POINT:USED (signed 16-bit) and header word 2 count all.
// Limits checked at open (one-line errors naming the file; docs/formats.md, "C3D"):
// 1..32767 labels (POINT:USED) of 1..255 characters, each parameter record within its
// signed 16-bit offset (255 labels of up to 128 characters), the whole parameter section
// within 255 blocks, and frame numbers up to 65535 (the header's 16-bit frame words and
// POINT:FRAMES). The tracker writes at most 32 x 16 = 512 labels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "formats/export_file.h"
#include "formats/trajectory_export.h"

namespace mocap {

inline constexpr float kC3dPointScale = -0.1f;  // float data; residual unit 0.1 mm
inline constexpr std::int64_t kC3dMaxFrame = 65535;
inline constexpr int kC3dMaxPoints = 32767;                 // POINT:USED is a signed 16-bit word
inline constexpr std::size_t kC3dLabelsPerParameter = 255;  // LABELS, LABELS2, ... each

class C3dWriter {
 public:
  static Expected<C3dWriter> open(const std::string& path, const TrajectoryLayout& layout);
  C3dWriter(C3dWriter&&) noexcept = default;
  C3dWriter& operator=(C3dWriter&&) noexcept = default;
  ~C3dWriter() = default;

  // One frame: layout.labels.size() samples. False after a write failure.
  bool write_frame(const TrajectorySample* samples) noexcept;
  // Pads the file to whole 512-byte blocks, flushes and closes. An error when a write
  // failed or fewer/more frames were written than the layout declared.
  Expected<void> close();
  const std::string& path() const noexcept { return file_.path(); }

 private:
  explicit C3dWriter(formats_detail::ExportFile file) : file_(std::move(file)) {}
  formats_detail::ExportFile file_;
  std::vector<unsigned char> frame_bytes_;  // one frame, sized at open
  std::size_t points_ = 0;
  std::int64_t frames_declared_ = 0;
  std::int64_t frames_written_ = 0;
};

// The header block and parameter section of a C3D file for `layout` (exposed for tests).
Expected<std::vector<unsigned char>> c3d_header_and_parameters(const TrajectoryLayout& layout);

}  // namespace mocap
