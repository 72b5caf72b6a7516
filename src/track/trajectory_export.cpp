// Design: see trajectory_export.h.
#include "track/trajectory_export.h"

#include <algorithm>

#include "core/median.h"
#include "formats/markers_csv.h"

namespace mocap {

Expected<double> frame_rate_hz(const std::vector<FrameEntry>& frames,
                               const std::string& frames_csv) {
  if (frames.size() < 2) {
    return make_error(frames_csv, "", "the frame rate of the exports needs at least 2 frames");
  }
  std::vector<double> periods_ns;
  periods_ns.reserve(frames.size() - 1);
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const std::int64_t df = frames[i].frame - frames[i - 1].frame;
    const std::int64_t dt = frames[i].timestamp_ns - frames[i - 1].timestamp_ns;
    if (df <= 0 || dt <= 0) {
      return make_error(frames_csv, "frame " + std::to_string(frames[i].frame),
                        "frame numbers and timestamps must increase to give a frame rate");
    }
    periods_ns.push_back(static_cast<double>(dt) / static_cast<double>(df));
  }
  return 1e9 / median_in_place(periods_ns);
}

std::vector<std::string> trajectory_labels(const TargetSet& targets) {
  std::vector<std::string> labels;
  for (const MarkerTarget& t : targets.bodies) {
    for (std::size_t m = 0; m < t.markers_body.size(); ++m)
      labels.push_back(t.name + "_m" + std::to_string(m));
  }
  return labels;
}

Expected<LabelledExports> LabelledExports::open(const LabelledExportPaths& paths,
                                                const TargetSet& targets,
                                                const std::vector<FrameEntry>& frames,
                                                const std::string& frames_csv) {
  LabelledExports e;
  int first = 0;
  for (const MarkerTarget& t : targets.bodies) {
    e.body_names_.push_back(t.name);
    e.first_trajectory_.push_back(first);
    first += static_cast<int>(t.markers_body.size());
  }
  e.frames_ = frames;
  e.samples_.assign(static_cast<std::size_t>(first), TrajectorySample{});
  auto csv = open_markers_csv(paths.markers_csv);
  if (!csv) return csv.error();
  e.markers_csv_.emplace(std::move(csv).value());
  if (paths.c3d.empty() && paths.trc.empty()) return e;

  auto rate = frame_rate_hz(frames, frames_csv);
  if (!rate) return rate.error();
  TrajectoryLayout layout;
  layout.labels = trajectory_labels(targets);
  for (const MarkerTarget& t : targets.bodies) {
    for (std::size_t m = 0; m < t.markers_body.size(); ++m) {
      layout.descriptions.push_back("marker " + std::to_string(m) + " of body " + t.name);
    }
  }
  layout.rate_hz = *rate;
  layout.frame_count = static_cast<std::int64_t>(frames.size());
  layout.first_frame = frames.front().frame + 1;
  if (!paths.c3d.empty()) {
    auto c3d = C3dWriter::open(paths.c3d, layout);
    if (!c3d) return c3d.error();
    e.c3d_.emplace(std::move(c3d).value());
  }
  if (!paths.trc.empty()) {
    auto trc = TrcWriter::open(paths.trc, layout);
    if (!trc) return trc.error();
    e.trc_.emplace(std::move(trc).value());
  }
  return e;
}

bool LabelledExports::write_frame(std::size_t index, const LabelledMarkers& labelled) noexcept {
  if (index >= frames_.size()) return false;
  const FrameEntry& fe = frames_[index];
  for (TrajectorySample& s : samples_) s.valid = false;
  for (int i = 0; i < labelled.count; ++i) {
    const LabelledMarker& l = labelled.items[static_cast<std::size_t>(i)];
    if (l.body < 0 || static_cast<std::size_t>(l.body) >= body_names_.size()) continue;
    write_marker_row(*markers_csv_, fe.frame, fe.timestamp_ns,
                     body_names_[static_cast<std::size_t>(l.body)], l.marker, l.X_world_mm,
                     l.residual_mm);
    ++marker_rows_;
    const auto t =
        static_cast<std::size_t>(first_trajectory_[static_cast<std::size_t>(l.body)] + l.marker);
    if (t >= samples_.size()) continue;
    TrajectorySample& s = samples_[t];
    s.valid = true;
    s.cameras = static_cast<std::uint8_t>(l.cameras & 0x7Fu);  // C3D: cameras 0..6 only
    s.X_mm = l.X_world_mm;
    s.residual_mm = l.residual_mm;
  }
  bool ok = true;
  if (c3d_) ok = c3d_->write_frame(samples_.data()) && ok;
  if (trc_) {
    const double time_s =
        static_cast<double>(fe.timestamp_ns - frames_.front().timestamp_ns) * 1e-9;
    ok = trc_->write_frame(fe.frame + 1, time_s, samples_.data()) && ok;
  }
  return ok;
}

Expected<void> LabelledExports::close() {
  Expected<void> first_error{};
  const auto keep = [&](Expected<void> r) {
    if (!r && first_error) first_error = r.error();
  };
  if (markers_csv_) keep(markers_csv_->close());
  if (c3d_) keep(c3d_->close());
  if (trc_) keep(trc_->close());
  return first_error;
}

}  // namespace mocap
