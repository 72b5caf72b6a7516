// Design: `mocap track` as a library call: runs a recording through the FrameProcessor
// frame by frame (files are read outside the timed region) and writes the spec's
// points.csv, poses.csv, angles.csv, markers.csv (labelled markers) and optionally
// stats.json and the labelled trajectories as C3D and TRC (trajectory_export.h). A missing frame
// file is a dropped frame (no 3D points for that frame); a damaged one is reported as a warning
// naming the file and treated as dropped, so one bad file never loses the rest.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "track/frame_processor.h"
#include "track/stats_json.h"
#include "track/truth.h"

namespace mocap {

struct OfflineTrackOptions {
  std::string recording_dir;
  std::string targets_path;
  std::string model_path;  // empty: no joint angles
  std::string out_dir;
  std::string stats_path;  // empty: no stats.json
  std::string c3d_path;    // empty: no C3D export
  std::string trc_path;    // empty: no TRC export
  std::string truth_dir;   // empty: no accuracy report (simulator ground truth, e.g. REC/gt)
  TrackerConfig config{};
  int detect_threads = 2;  // 1: every camera on the calling thread; 2: ParallelDetect
  std::function<void(std::int64_t done, std::int64_t total)> progress;
  std::function<void(const std::string& message)> warn;  // one line per problem
};

struct OfflineTrackResult {
  std::int64_t frames = 0;
  std::int64_t frames_missing = 0;  // at least one camera's file absent
  std::int64_t frames_damaged = 0;  // at least one camera's file unreadable (warned)
  std::int64_t points = 0;
  std::vector<std::string> body_names;
  std::vector<std::int64_t> body_found;  // frames in which each body was found
  std::int64_t angle_rows = 0;
  // Coverage per joint (model order): frames with the angle valid, by how it was solved.
  std::vector<std::string> joint_names;
  std::vector<std::int64_t> joint_poses, joint_chain;
  std::int64_t marker_rows = 0;  // rows of markers.csv (labelled markers)
  std::unique_ptr<TrackStats> stats;
  std::optional<AccuracyReport> accuracy;
};

Expected<OfflineTrackResult> track_recording(const OfflineTrackOptions& options);

// Multi-line human summary of a result (frames, detections, timings, accuracy).
std::string format_track_summary(const OfflineTrackResult& result);

}  // namespace mocap
