// Design: the labelled-marker outputs of `mocap track`, fed from one list per frame
// (label_markers()): markers.csv always, and optionally the C3D and TRC trajectory
// exports (src/formats). One trajectory per model marker of targets.yaml, labelled
// `BODY_mN`, in targets.yaml order; frame i of the exports is row i of frames.csv (first
// frame number = frames.csv's first `frame` + 1, as C3D and TRC count from 1); the rate
// comes from the frames.csv timestamps (frame_rate_hz). Everything streams: per frame
// only one sample per trajectory is held (sized at open).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/c3d_writer.h"
#include "formats/csv_outputs.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "formats/trc_writer.h"
#include "track/labelled_markers.h"

namespace mocap {

// Frames per second of a recording: 1e9 / the median of (timestamp step / frame-number
// step) over consecutive rows. Errors (naming `frames_csv`) with fewer than two frames or
// timestamps that do not increase.
Expected<double> frame_rate_hz(const std::vector<FrameEntry>& frames,
                               const std::string& frames_csv);

// `BODY_mN` for every marker of every body, in targets.yaml order.
std::vector<std::string> trajectory_labels(const TargetSet& targets);

struct LabelledExportPaths {
  std::string markers_csv;  // required
  std::string c3d;          // empty: none
  std::string trc;          // empty: none
};

class LabelledExports {
 public:
  static Expected<LabelledExports> open(const LabelledExportPaths& paths, const TargetSet& targets,
                                        const std::vector<FrameEntry>& frames,
                                        const std::string& frames_csv);
  // Writes frame `index` (row of frames.csv) to every output; false after a C3D/TRC write
  // failure (close() then names the file).
  bool write_frame(std::size_t index, const LabelledMarkers& labelled) noexcept;
  std::int64_t marker_rows() const noexcept { return marker_rows_; }
  // Closes all outputs; the first error wins.
  Expected<void> close();

 private:
  LabelledExports() = default;
  std::vector<std::string> body_names_;
  std::vector<int> first_trajectory_;  // per body: index of its marker 0
  std::vector<FrameEntry> frames_;
  std::optional<CsvFile> markers_csv_;
  std::optional<C3dWriter> c3d_;
  std::optional<TrcWriter> trc_;
  std::vector<TrajectorySample> samples_;
  std::int64_t marker_rows_ = 0;
};

}  // namespace mocap
