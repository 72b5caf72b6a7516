#include "discover/frame_points.h"

#include <array>
#include <optional>

#include "detect/blob_detector.h"
#include "formats/recording.h"
#include "stereo/stereo_triangulator.h"

namespace mocap::discover {

Expected<PointSequence> triangulate_recording(const std::string& recording_dir,
                                              const PointsProgress& cb) {
  auto rec = Recording::open(recording_dir);
  if (!rec) return rec.error();
  const Rig& rig = rec->rig();
  if (rig.cameras.size() < 2)
    return Error{recording_dir + "/rig.yaml: discover needs two cameras, the rig has " +
                 std::to_string(rig.cameras.size())};
  // The tracker's detector settings (src/track TrackerConfig): round blobs only.
  detect::DetectorConfig dcfg;
  dcfg.max_elongation = 1.3;
  std::array<std::optional<detect::BlobDetector>, 2> detectors;
  std::array<detect::BlobList, 2> blobs;
  for (std::size_t c = 0; c < 2; ++c) {
    auto d = detect::BlobDetector::create(dcfg, rig.cameras[c].width, rig.cameras[c].height);
    if (!d)
      return Error{recording_dir + ": detection (" + rig.cameras[c].name +
                   "): " + d.error().message};
    detectors[c].emplace(std::move(d).value());
    blobs[c] = detectors[c]->make_blob_list();
  }
  StereoConfig scfg;
  auto stereo = StereoTriangulator::create(rig, scfg, 0, 1);
  if (!stereo) return Error{recording_dir + "/rig.yaml: stereo: " + stereo.error().message};
  PointList points(scfg.max_candidates);
  std::array<std::vector<Vec2>, 2> px;
  for (auto& v : px) v.resize(static_cast<std::size_t>(scfg.max_points_per_camera));

  constexpr std::uint32_t kSuspect = detect::kBlobTouchesBorder | detect::kBlobMerged |
                                     detect::kBlobSplit | detect::kBlobTruncated;
  PointSequence seq;
  std::optional<Error> first_error;
  std::size_t loaded_frames = 0;
  std::array<Image, 2> images;
  const auto& frames = rec->frames();
  seq.frames.reserve(frames.size());
  for (std::size_t fi = 0; fi < frames.size(); ++fi) {
    const FrameEntry& fe = frames[fi];
    FramePoints fp;
    fp.frame = fe.frame;
    fp.timestamp_ns = fe.timestamp_ns;
    bool both = true;
    for (std::size_t c = 0; c < 2; ++c) {
      auto loaded = rec->load_frame(static_cast<int>(c), fe.frame, images[c]);
      blobs[c].clear();
      if (!loaded) {  // a damaged frame is skipped (as in `mocap calibrate`), and reported
        if (!first_error) first_error = loaded.error();
        if (cb.warn)
          cb.warn(loaded.error().message + " (frame " + std::to_string(fe.frame) + " skipped)");
        both = false;
        continue;
      }
      if (*loaded != FrameLoad::kOk) {
        both = false;
        continue;
      }
      detectors[c]->detect(images[c].view(), blobs[c]);
    }
    if (both) ++loaded_frames;
    if (!both) {
      ++seq.frames_missing_camera;
    } else {
      std::array<int, 2> n{};
      for (std::size_t c = 0; c < 2; ++c) {
        const std::size_t count = std::min(blobs[c].size(), px[c].size());
        for (std::size_t i = 0; i < count; ++i) px[c][i] = Vec2(blobs[c][i].x_px, blobs[c][i].y_px);
        n[c] = static_cast<int>(count);
      }
      stereo->process(px[0].data(), n[0], px[1].data(), n[1], points);
      for (const Point3& p : points) {
        bool keep = !p.ambiguous;
        for (std::size_t c = 0; c < 2 && keep; ++c) {
          const int b = p.blob_index[c];
          keep = b >= 0 && static_cast<std::size_t>(b) < blobs[c].size() &&
                 (blobs[c][static_cast<std::size_t>(b)].flags & kSuspect) == 0U;
        }
        if (keep)
          fp.X_world_mm.push_back(p.X_world);
        else
          ++seq.points_dropped;
      }
    }
    seq.frames.push_back(std::move(fp));
    if (cb.progress)
      cb.progress(static_cast<std::int64_t>(fi + 1), static_cast<std::int64_t>(frames.size()));
  }
  if (loaded_frames == 0 && first_error) return *first_error;
  return seq;
}

}  // namespace mocap::discover
