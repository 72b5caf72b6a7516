// Design: see frame_recorder.h. The writer thread's side of FrameRecorder: one frame set
// (a Unit) written to the recording, images or blob lists and then its frames.csv row, and
// the units of a drain put in frame order first. frame_recorder.cpp has the taps, the
// pairing and the thread.
#include <algorithm>

#include "formats/recording.h"
#include "pipeline/record/frame_recorder.h"

namespace mocap::record {

Expected<void> FrameRecorder::write_blobs(int camera, std::int64_t number, const Slot& s) {
  auto r = blob_files_[static_cast<std::size_t>(camera)].append(number, s.timestamp_ns, s.blobs);
  if (!r) return r;
  blob_lists_written_.add();
  if (s.kept < 0) return {};
  r = files_.write_image(camera, number, s.view);
  if (r) images_written_.add();
  return r;
}

void FrameRecorder::write_unit(const Unit& u) {
  const bool skip = error_.has_value() || u.frame <= last_frame_;
  if (!skip) {
    // Recordings number their frames from 0: the first frame written is frame 0 (the
    // same as the tap's numbering unless every image of the first frames was dropped).
    if (first_frame_ < 0) first_frame_ = u.frame;
    const std::int64_t number = u.frame - first_frame_;
    const int n = camera_count();
    std::array<int, kMaxCameras> written;
    written.fill(-1);
    bool has[kMaxCameras] = {};  // the camera's image (or blob list) is in the recording
    Expected<void> r;
    for (int c = 0; c < n && r; ++c) {
      if (u.slot[c] < 0) continue;
      const Slot& s = slots_[static_cast<std::size_t>(c)][static_cast<std::size_t>(u.slot[c])];
      if (s.missing) continue;
      if (options_.blobs) {  // its chunk stays if the row fails: not in frames.csv, never read
        r = write_blobs(c, number, s);
        if (r && s.kept >= 0) written[c] = c;
        has[c] = static_cast<bool>(r);
        continue;
      }
      r = files_.write_image(c, number, s.view);
      if (r) written[c] = c;
      has[c] = static_cast<bool>(r);
    }
    int ts_cam = 0;  // the first camera with an image slot gives the timestamp
    while (ts_cam + 1 < n && u.slot[ts_cam] < 0) ++ts_cam;
    const Slot& ts =
        slots_[static_cast<std::size_t>(ts_cam)][static_cast<std::size_t>(u.slot[ts_cam])];
    if (r) r = files_.append_row(number, ts.timestamp_ns);
    if (!r) {  // the frame is not in frames.csv: its files go too
      for (int c : written)
        if (c >= 0) files_.remove_image(c, number);
      error_ = r.error();
      failed_.store(true, std::memory_order_release);  // pairs with failed()'s acquire
      not_written_.add();
    } else {
      last_frame_ = u.frame;
      frames_written_.add();
      for (int c = 0; c < n; ++c)
        if (!has[c]) without_image_[static_cast<std::size_t>(c)].add();
      if (!options_.blobs)
        for (int c : written)
          if (c >= 0) images_written_.add();
      std::uint64_t bytes = files_.bytes_written();
      for (const BlobFileWriter& w : blob_files_) bytes += w.bytes();
      bytes_written_.add(bytes - bytes_written_.get());
    }
  } else {
    not_written_.add();
  }
  for (int c = 0; c < camera_count(); ++c) free_slot(c, u.slot[c]);
}

void FrameRecorder::write_units() {
  std::sort(units_.begin(), units_.end(),
            [](const Unit& a, const Unit& b) { return a.frame < b.frame; });
  // The cameras of one frame dropped by the matcher one by one (a camera missed the
  // frame) arrive as units of one camera each: merged into one unit per frame.
  std::size_t out = 0;
  for (std::size_t i = 0; i < units_.size(); ++i) {
    if (out > 0 && units_[out - 1].frame == units_[i].frame) {
      Unit& m = units_[out - 1];
      for (int c = 0; c < camera_count(); ++c) {
        if (m.slot[c] < 0) {
          m.slot[c] = units_[i].slot[c];
        } else if (units_[i].slot[c] >= 0) {  // the same camera twice: cannot happen
          free_slot(c, units_[i].slot[c]);
          not_written_.add();
        }
      }
    } else {
      units_[out++] = units_[i];
    }
  }
  units_.resize(out);
  for (const Unit& u : units_) write_unit(u);
  units_.clear();
}

}  // namespace mocap::record
