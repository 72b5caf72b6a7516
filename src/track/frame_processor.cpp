// Design: see frame_processor.h.
#include "track/frame_processor.h"

#include <algorithm>
#include <utility>

#include "core/latency_stats.h"

namespace mocap {

Expected<FrameProcessor> FrameProcessor::create(const Rig& rig, const TargetSet& targets,
                                                const JointModel* model,
                                                const TrackerConfig& config) {
  if (rig.cameras.size() < 2) {
    return Error{"rig: the tracker needs two cameras (the stereo pair), the rig has " +
                 std::to_string(rig.cameras.size())};
  }
  std::array<std::optional<detect::BlobDetector>, 2> dets;
  for (int c = 0; c < 2; ++c) {
    const CameraModel& cam = rig.cameras[static_cast<std::size_t>(c)];
    auto d = detect::BlobDetector::create(config.detect, cam.width, cam.height);
    if (!d) return Error{"detection (" + cam.name + "): " + d.error().message};
    dets[static_cast<std::size_t>(c)].emplace(std::move(d).value());
  }
  auto stereo = StereoTriangulator::create(rig, config.stereo, 0, 1);
  if (!stereo) return Error{"stereo: " + stereo.error().message};
  auto ident = Identifier::create(targets, config.identify);
  if (!ident) return Error{"identification: " + ident.error().message};

  std::optional<kinematics::JointAngleSolver> angles;
  JointModel model_copy;
  if (model != nullptr) {
    auto solver = kinematics::JointAngleSolver::create(*model, targets.bodies.size());
    if (!solver) return Error{"joint angles: " + solver.error().message};
    angles.emplace(std::move(solver).value());
    model_copy = *model;
  }
  FrameProcessor p(rig, targets, std::move(model_copy), {std::move(*dets[0]), std::move(*dets[1])},
                   std::move(stereo).value(), std::move(ident).value(), std::move(angles));
  for (int c = 0; c < 2; ++c) {
    auto shape = MarkerShapeModel::create(rig.cameras[static_cast<std::size_t>(c)],
                                          targets.marker_diameter_mm, config.marker_shape);
    if (!shape) return shape.error();
    p.shapes_.push_back(std::move(shape).value());
  }
  auto selector = PointSelector::create(config.stereo.max_candidates,
                                        config.stereo.max_points_per_camera, config.selection);
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
  }
  p.warnings_ = p.identifier_.warnings();
  if (p.chain_) {
    for (const std::string& w : p.chain_->model().warnings())
      p.warnings_.push_back("chain tracking: " + w);
  }
  for (auto& c : p.centroids_px_) c.resize(static_cast<std::size_t>(config.detect.max_blobs));
  p.measured_.resize(static_cast<std::size_t>(std::max(1, config.stereo.max_candidates)));
  p.body_views_.resize(targets.bodies.size());
  return p;
}

FrameProcessor::FrameProcessor(Rig rig, TargetSet targets, JointModel model,
                               std::array<detect::BlobDetector, 2> detectors,
                               StereoTriangulator stereo, Identifier identifier,
                               std::optional<kinematics::JointAngleSolver> angles)
    : rig_(std::move(rig)),
      targets_(std::move(targets)),
      model_(std::move(model)),
      detectors_(std::move(detectors)),
      stereo_(std::move(stereo)),
      identifier_(std::move(identifier)),
      angles_(std::move(angles)) {}

FrameOutput FrameProcessor::make_output() const {
  FrameOutput out;
  for (std::size_t c = 0; c < 2; ++c) out.blobs[c] = detectors_[c].make_blob_list();
  out.points.set_capacity(stereo_.config().max_candidates);
  out.poses.count = identifier_.body_count();
  if (angles_) out.angles = angles_->make_output();
  return out;
}

bool FrameProcessor::detect_camera(int camera, const ImageView& image,
                                   detect::BlobList& out) noexcept {
  if (camera < 0 || camera > 1) return false;
  return detectors_[static_cast<std::size_t>(camera)].detect(image, out);
}

bool FrameProcessor::process(const ImageView* cam0, const ImageView* cam1,
                             std::int64_t timestamp_ns, FrameOutput& out) noexcept {
  const std::int64_t t0 = monotonic_ns();
  const ImageView* views[2] = {cam0, cam1};
  for (std::size_t c = 0; c < 2; ++c) {
    out.blobs[c].clear();
    out.camera_present[c] = views[c] != nullptr;
    if (views[c] != nullptr) detect_camera(static_cast<int>(c), *views[c], out.blobs[c]);
  }
  out.times.detect = monotonic_ns() - t0;
  const bool ok = process_blobs(timestamp_ns, out);
  out.times.frame = monotonic_ns() - t0;
  return ok;
}

bool FrameProcessor::process_blobs(std::int64_t timestamp_ns, FrameOutput& out) noexcept {
  // Stereo + triangulation: only when both cameras delivered this frame.
  std::int64_t t = monotonic_ns();
  out.points.clear();
  if (out.camera_present[0] && out.camera_present[1]) {
    std::array<int, 2> n{};
    for (std::size_t c = 0; c < 2; ++c) {
      const detect::BlobList& blobs = out.blobs[c];
      std::vector<Vec2>& px = centroids_px_[c];
      const std::size_t count = std::min(blobs.size(), px.size());
      for (std::size_t i = 0; i < count; ++i) px[i] = Vec2(blobs[i].x_px, blobs[i].y_px);
      n[c] = static_cast<int>(count);
    }
    stereo_.process(centroids_px_[0].data(), n[0], centroids_px_[1].data(), n[1], out.points);
  }
  std::int64_t now = monotonic_ns();
  out.times.triangulate = now - t;

  // Identification.
  t = now;
  const int n_points = std::min(out.points.size(), static_cast<int>(measured_.size()));
  for (int i = 0; i < n_points; ++i) {
    const Point3& p = out.points[i];
    MeasuredPoint& m = measured_[static_cast<std::size_t>(i)];
    m.X_world = p.X_world;
    m.blob_index = {p.blob_index[0], p.blob_index[1]};
    m.partial = false;
    for (int c = 0; c < 2; ++c) {
      const int b = p.blob_index[static_cast<std::size_t>(c)];
      if (!whole_marker_view(c, out.blobs[static_cast<std::size_t>(c)], b, p.X_world))
        m.partial = true;
    }
  }
  measured_count_ = n_points;
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
        a.solved_by = chain_result_.joints[j].solved_by;
        a.sd_rad = chain_result_.joints[j].sd_rad;
      }
      chain_->remember(out.poses, timestamp_ns);
    }
  }
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
  chain_->solve(measured_.data(), n_points, timestamp_ns, out.poses, chain_result_);
  for (int b = 0; b < out.poses.count; ++b) {
    const auto ub = static_cast<std::size_t>(b);
    BodyPose& bp = out.poses.bodies[ub];
    bp.from_chain = false;
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
}

}  // namespace mocap
