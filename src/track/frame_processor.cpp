// Design: see frame_processor.h.
#include "track/frame_processor.h"

#include <algorithm>
#include <bit>
#include <utility>

#include "core/clock.h"

namespace mocap {

Expected<FrameProcessor> FrameProcessor::create(const Rig& rig, const TargetSet& targets,
                                                const JointModel* model,
                                                const TrackerConfig& config) {
  const int n_cams = static_cast<int>(rig.cameras.size());
  if (n_cams < kMinCameras || n_cams > kMaxCameras) {
    return Error{"rig: the tracker takes " + std::to_string(kMinCameras) + " to " +
                 std::to_string(kMaxCameras) + " cameras, the rig has " + std::to_string(n_cams)};
  }
  std::vector<detect::BlobDetector> dets;
  for (const CameraModel& cam : rig.cameras) {
    auto d = detect::BlobDetector::create(config.detect, cam.width, cam.height);
    if (!d) return Error{"detection (" + cam.name + "): " + d.error().message};
    dets.push_back(std::move(d).value());
  }
  std::array<CameraPair, kMaxCameraPairs> camera_pairs{};
  const int n_pairs = enumerate_camera_pairs(n_cams, camera_pairs);
  std::vector<StereoTriangulator> pairs;
  for (int k = 0; k < n_pairs; ++k) {
    const CameraPair cp = camera_pairs[static_cast<std::size_t>(k)];
    auto stereo = StereoTriangulator::create(rig, config.stereo, cp.a, cp.b);
    if (!stereo) return Error{"stereo: " + stereo.error().message};
    pairs.push_back(std::move(stereo).value());
  }
  MultiViewConfig mvc = config.multiview;
  mvc.max_points_per_camera = config.stereo.max_points_per_camera;
  mvc.max_hypotheses = std::max(1, config.stereo.max_candidates) * std::max(1, n_pairs);
  if (targets.marker_diameter_mm > 0.0) mvc.marker_radius_mm = 0.5 * targets.marker_diameter_mm;
  auto merger = MultiViewMerger::create(rig, mvc);
  if (!merger) return Error{"multi-view: " + merger.error().message};
  IdentifyConfig id_config = config.identify;
  id_config.cameras = n_cams;  // the blob occupancy of the rig's cameras only
  auto ident = Identifier::create(targets, id_config);
  if (!ident) return Error{"identification: " + ident.error().message};

  std::optional<kinematics::JointAngleSolver> angles;
  JointModel model_copy;
  if (model != nullptr) {
    auto solver = kinematics::JointAngleSolver::create(*model, targets.bodies.size());
    if (!solver) return Error{"joint angles: " + solver.error().message};
    angles.emplace(std::move(solver).value());
    model_copy = *model;
  }
  FrameProcessor p(rig, targets, std::move(model_copy), std::move(dets), std::move(pairs),
                   std::move(merger).value(), std::move(ident).value(), std::move(angles));
  for (const CameraModel& cam : rig.cameras) {
    auto shape = MarkerShapeModel::create(cam, targets.marker_diameter_mm, config.marker_shape);
    if (!shape) return shape.error();
    p.shapes_.push_back(std::move(shape).value());
  }
  auto selector = PointSelector::create(
      config.stereo.max_candidates, config.stereo.max_points_per_camera, config.selection, n_cams);
  if (!selector) return selector.error();
  p.selector_ = std::move(selector).value();
  if (model != nullptr) {
    auto chain_model = ChainModel::create(*model, targets);
    if (!chain_model) return Error{"chain tracking: " + chain_model.error().message};
    ChainConfig cc = config.chain;
    const IdentifyConfig& ic = config.identify;
    if (ic.point_sigma_mm > 0.0) cc.point_sigma_mm = ic.point_sigma_mm;
    cc.partial_sigma_mm = ic.partial_sigma_mm;
    cc.confidence = ic.consistency_confidence;
    if (ic.max_angular_speed_deg_per_s > 0.0)
      cc.max_angular_speed_deg_per_s = ic.max_angular_speed_deg_per_s;
    auto chain = ChainSolver::create(std::move(chain_model).value(), cc);
    if (!chain) return Error{"chain tracking: " + chain.error().message};
    p.chain_.emplace(std::move(chain).value());
    std::vector<JointType> types;
    for (const JointSpec& j : model->joints) types.push_back(j.type);
    auto rates = kinematics::JointRateFilter::create(config.velocity, types);
    if (!rates) return rates.error();
    p.rates_.emplace(std::move(rates).value());
  }
  // The point noise as chain tracking takes it (identification's, else the chain's own).
  const double point_sigma_mm = config.identify.point_sigma_mm > 0.0
                                    ? config.identify.point_sigma_mm
                                    : config.chain.point_sigma_mm;
  auto motion = BodyMotion::create(targets, point_sigma_mm, config.velocity);
  if (!motion) return motion.error();
  p.body_motion_.emplace(std::move(motion).value());
  p.warnings_ = p.identifier_.warnings();
  if (p.chain_) {
    for (const std::string& w : p.chain_->model().warnings())
      p.warnings_.push_back("chain tracking: " + w);
  }
  p.centroids_px_.assign(static_cast<std::size_t>(n_cams),
                         std::vector<Vec2>(static_cast<std::size_t>(config.detect.max_blobs)));
  if (n_cams > 2) {
    p.pair_points_.assign(static_cast<std::size_t>(n_pairs),
                          PointList(config.stereo.max_candidates));
    for (const CameraModel& cam : rig.cameras) {
      auto u = BlobUndistorter::create(cam, config.stereo.max_points_per_camera);
      if (!u) return u.error();
      p.undistorters_.push_back(std::move(u).value());
    }
  }
  p.measured_.resize(static_cast<std::size_t>(std::max(1, config.stereo.max_candidates)));
  p.partial_sigma_mm_.assign(p.measured_.size(), 0.0);
  p.marker_radius_mm_ = 0.5 * targets.marker_diameter_mm;
  p.fallback_partial_sigma_mm_ = config.identify.partial_sigma_mm;
  p.body_views_.resize(targets.bodies.size());
  return p;
}

FrameProcessor::FrameProcessor(Rig rig, TargetSet targets, JointModel model,
                               std::vector<detect::BlobDetector> detectors,
                               std::vector<StereoTriangulator> pairs, MultiViewMerger merger,
                               Identifier identifier,
                               std::optional<kinematics::JointAngleSolver> angles)
    : rig_(std::move(rig)),
      targets_(std::move(targets)),
      model_(std::move(model)),
      detectors_(std::move(detectors)),
      pairs_(std::move(pairs)),
      merger_(std::move(merger)),
      identifier_(std::move(identifier)),
      angles_(std::move(angles)) {}

FrameOutput FrameProcessor::make_output() const {
  FrameOutput out;
  for (const detect::BlobDetector& d : detectors_) out.blobs.push_back(d.make_blob_list());
  out.points.set_capacity(pairs_.front().config().max_candidates);
  out.poses.count = identifier_.body_count();
  if (angles_) out.angles = angles_->make_output();
  out.body_rates = body_motion_->make_output();
  for (const BlobUndistorter& u : undistorters_) out.undistorted.push_back(u.make_store());
  return out;
}

void FrameProcessor::undistort_camera(int camera, const detect::BlobList& blobs,
                                      UndistortedStore& out) const noexcept {
  out.received = -1;
  if (camera < 0 || static_cast<std::size_t>(camera) >= undistorters_.size()) return;
  // The blobs triangulate() takes: the first max_points_per_camera.
  const auto uc = static_cast<std::size_t>(camera);
  const int n = static_cast<int>(std::min(blobs.size(), centroids_px_[uc].size()));
  undistorters_[uc].undistort_into(
      [&](int i) noexcept {
        const detect::Blob& b = blobs[static_cast<std::size_t>(i)];
        return Vec2(b.x_px, b.y_px);
      },
      n, out);
}

bool FrameProcessor::detect_camera(int camera, const ImageView& image,
                                   detect::BlobList& out) noexcept {
  if (camera < 0 || camera >= camera_count()) return false;
  return detectors_[static_cast<std::size_t>(camera)].detect(image, out);
}

bool FrameProcessor::process(std::span<const ImageView* const> views, std::int64_t timestamp_ns,
                             FrameOutput& out) noexcept {
  const std::int64_t t0 = monotonic_ns();
  for (int c = 0; c < camera_count(); ++c) {
    const auto uc = static_cast<std::size_t>(c);
    const ImageView* view = uc < views.size() ? views[uc] : nullptr;
    out.blobs[uc].clear();
    out.camera_present[uc] = view != nullptr;
    if (view != nullptr) detect_camera(c, *view, out.blobs[uc]);
  }
  out.times.detect = monotonic_ns() - t0;
  const bool ok = process_blobs(timestamp_ns, out);
  out.times.frame = monotonic_ns() - t0;
  return ok;
}

void FrameProcessor::triangulate(FrameOutput& out) noexcept {
  triangulate_points(out);
  // Consumed: the next frame's are made anew by its detection (or here).
  for (UndistortedStore& u : out.undistorted) u.received = -1;
}

void FrameProcessor::triangulate_points(FrameOutput& out) noexcept {
  out.points.clear();
  const int n_cams = camera_count();
  const Vec2* px[kMaxCameras] = {};
  int n[kMaxCameras] = {};
  int present = 0;
  for (int c = 0; c < n_cams; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    if (!out.camera_present[uc]) continue;
    ++present;
    const detect::BlobList& blobs = out.blobs[uc];
    std::vector<Vec2>& centroids = centroids_px_[uc];
    const std::size_t count = std::min(blobs.size(), centroids.size());
    for (std::size_t i = 0; i < count; ++i) centroids[i] = Vec2(blobs[i].x_px, blobs[i].y_px);
    px[c] = centroids.data();
    n[c] = static_cast<int>(count);
  }
  if (present < 2) return;
  if (n_cams == 2) {  // the stereo pair straight into the output: the paper's path
    pairs_.front().process(px[0], n[0], px[1], n[1], out.points);
    stereo_total_ = pairs_.front().counters();
    return;
  }
  // Each camera's blobs undistorted once, for all its pairs (the same result as each
  // pair undistorting them): where they were detected, when that thread did it.
  UndistortedBlobs views[kMaxCameras];
  for (int c = 0; c < n_cams; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    if (!out.camera_present[uc]) continue;
    if (uc < out.undistorted.size() && out.undistorted[uc].received == n[c]) {
      views[c] = out.undistorted[uc].view(px[c]);
    } else {
      views[c] = undistorters_[uc].undistort(px[c], n[c]);
      ++undistorted_late_;
    }
  }
  // Pair by pair into the merge: a pair of blobs that earlier pairs settled (both in
  // points seen by three or more cameras) is not triangulated again.
  merger_.begin_frame(px, n);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    StereoTriangulator& st = pairs_[k];
    const int a = st.camera_a(), b = st.camera_b();
    if (!out.camera_present[static_cast<std::size_t>(a)] ||
        !out.camera_present[static_cast<std::size_t>(b)])
      continue;
    st.process(views[a], views[b], pair_points_[k],
               SettledBlobs{merger_.settled_blobs(a), merger_.settled_blobs(b)});
    merger_.add_pair(pair_points_[k], px);
  }
  merger_.finish(px, out.points);
  multiview_total_ = merger_.counters();
  multiview_total_.undistorted_late = undistorted_late_;
  StereoCounters total;
  for (const StereoTriangulator& st : pairs_) total += st.counters();
  stereo_total_ = total;
}

void FrameProcessor::measure_points(FrameOutput& out) noexcept {
  const int n_points = std::min(out.points.size(), static_cast<int>(measured_.size()));
  const Vec2* px[kMaxCameras] = {};
  for (int c = 0; c < camera_count(); ++c)
    px[c] = centroids_px_[static_cast<std::size_t>(c)].data();
  for (int i = 0; i < n_points; ++i) {
    Point3& p = out.points[i];
    // Which views look like a whole marker at the point's position.
    BlobRefs whole = p.blob_index;
    int n_whole = 0;
    for (CameraMask seen = p.blob_index.mask(); seen != 0; seen &= seen - 1) {
      const int c = std::countr_zero(seen);
      const int b = p.blob_index[c];
      if (whole_marker_view(c, out.blobs[static_cast<std::size_t>(c)], b, p.X_world))
        ++n_whole;
      else
        whole[c] = -1;
    }
    const int views = p.blob_index.count();
    bool partial = n_whole < views;
    if (partial && n_whole >= 2) {
      // Enough whole views: the point is measured from them alone (its other blobs
      // still belong to it, for exclusivity and the reported set).
      Point3 refit = p;
      refit.blob_index = whole;
      if (merger_.refit(refit, px)) {
        p.X_world = refit.X_world;
        p.reproj_px = refit.reproj_px;
        partial = false;
      }
    }
    MeasuredPoint& m = measured_[static_cast<std::size_t>(i)];
    m.X_world = p.X_world;
    m.blob_index = p.blob_index;
    m.partial = partial;
    // A partial point's noise for the chain (docs/chain.md, "Partial markers"): the
    // centroid shift of its most hidden view, b(f) x the ball's radius.
    double sigma = 0.0;
    if (partial) {
      double shift = 0.0;
      for (CameraMask seen = p.blob_index.mask(); seen != 0; seen &= seen - 1) {
        const int c = std::countr_zero(seen);
        const int b = p.blob_index[c];
        if (whole[c] >= 0) continue;
        const detect::BlobList& blobs = out.blobs[static_cast<std::size_t>(c)];
        const double f = static_cast<std::size_t>(b) < blobs.size()
                             ? shapes_[static_cast<std::size_t>(c)].visible_fraction(
                                   blobs[static_cast<std::size_t>(b)], p.X_world)
                             : 0.0;
        // The view's image shift moves the point along the best partner view's ray:
        // by the shift / sin(angle between the two rays) (docs/chain.md).
        const Vec3 ray =
            (p.X_world - rig_.cameras[static_cast<std::size_t>(c)].center_world()).normalized();
        double sin_best = 0.0;
        for (CameraMask others = p.blob_index.mask() & ~(CameraMask{1} << c); others != 0;
             others &= others - 1) {
          const int o = std::countr_zero(others);
          const Vec3 other =
              (p.X_world - rig_.cameras[static_cast<std::size_t>(o)].center_world()).normalized();
          sin_best = std::max(sin_best, ray.cross(other).norm());
        }
        shift = std::max(shift, partial_centroid_shift(f) / std::max(sin_best, 0.05));
      }
      sigma = marker_radius_mm_ > 0.0 ? shift * marker_radius_mm_ : fallback_partial_sigma_mm_;
    }
    partial_sigma_mm_[static_cast<std::size_t>(i)] = sigma;
  }
  measured_count_ = n_points;
}

bool FrameProcessor::process_blobs(std::int64_t timestamp_ns, FrameOutput& out) noexcept {
  // Correspondence + triangulation over the cameras that delivered this frame.
  std::int64_t t = monotonic_ns();
  triangulate(out);
  std::int64_t now = monotonic_ns();
  out.times.triangulate = now - t;

  // Identification.
  t = now;
  measure_points(out);
  const int n_points = measured_count_;
  const bool identified = identifier_.identify(measured_.data(), n_points, timestamp_ns, out.poses);
  // Kinematic-chain tracking (with a model): bodies solved through their joints join the
  // poses, so the point selection below counts their points as used.
  track_chain(n_points, timestamp_ns, out);
  // Which candidates are reported (points.csv): one per blob, chosen by the evidence.
  selector_.select(out.poses, timestamp_ns, out.points);
  now = monotonic_ns();
  out.times.identify = now - t;

  // Joint angles.
  t = now;
  if (angles_) {
    for (std::size_t b = 0; b < body_views_.size(); ++b) {
      body_views_[b].found = out.poses.bodies[b].found;
      body_views_[b].T_world_body = out.poses.bodies[b].T_world_body;
    }
    angles_->compute(body_views_.data(), out.angles);
    if (chain_) {
      for (std::size_t j = 0; j < out.angles.joints.size() && j < chain_result_.joints.size();
           ++j) {
        kinematics::JointAngle& a = out.angles.joints[j];
        if (!a.valid) continue;
        // Two found bodies that disagree with the calibrated joint (chain_poses.cpp):
        // one pose is wrong, so is the angle.
        if (chain_result_.joints[j].inconsistent) a.valid = false;
        a.solved_by = chain_result_.joints[j].solved_by;
        a.sd_rad = chain_result_.joints[j].sd_rad;
      }
      chain_->remember(out.poses, timestamp_ns);
    }
    if (rates_) rates_->update(timestamp_ns, out.angles);
  }
  body_motion_->update(timestamp_ns, out.poses, out.body_rates);
  out.times.angles = monotonic_ns() - t;
  return identified;
}

bool FrameProcessor::whole_marker_view(int camera, const detect::BlobList& blobs, int blob,
                                       const Vec3& X_world) const noexcept {
  if (blob < 0 || static_cast<std::size_t>(blob) >= blobs.size()) return true;
  const detect::BlobList::Levels& lv = blobs.levels();
  const ImageNoise noise{lv.background_dn, lv.noise_dn, lv.threshold_dn};
  return shapes_[static_cast<std::size_t>(camera)]
      .check(blobs[static_cast<std::size_t>(blob)], X_world, noise)
      .whole;
}

void FrameProcessor::track_chain(int n_points, std::int64_t timestamp_ns,
                                 FrameOutput& out) noexcept {
  if (!chain_) return;
  chain_->solve(measured_.data(), n_points, timestamp_ns, out.poses, chain_result_,
                partial_sigma_mm_.data());
  for (int b = 0; b < out.poses.count; ++b) {
    const auto ub = static_cast<std::size_t>(b);
    BodyPose& bp = out.poses.bodies[ub];
    bp.from_chain = false;
    if (chain_result_.refined_body[ub]) {  // refitted with its joint centre (chain_poses.cpp)
      bp.T_world_body = chain_result_.T_world_body[ub];
      bp.point_index_of_marker = chain_result_.point_index_of_marker[ub];
      bp.markers = chain_result_.markers[ub];
      bp.rms_mm = chain_result_.rms_mm[ub];
    }
    if (!chain_result_.chain_body[ub]) continue;
    bp.found = true;
    bp.from_chain = true;
    bp.from_prior = false;
    bp.T_world_body = chain_result_.T_world_body[ub];
    bp.markers = chain_result_.markers[ub];
    bp.rms_mm = chain_result_.rms_mm[ub];
    bp.score = 0.0;
    bp.point_index_of_marker = chain_result_.point_index_of_marker[ub];
    ++out.poses.found;
  }
}

void FrameProcessor::reset() noexcept {
  if (chain_) chain_->reset();
  identifier_.reset();
  selector_.reset();
  if (angles_) angles_->reset();
  if (rates_) rates_->reset();
  body_motion_->reset();
}

}  // namespace mocap
