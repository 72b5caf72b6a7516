// Design: kinematic-chain tracking. After rigid-target identification, a body that was
// not found on its own (fewer than 3 usable markers, or a rejected solution) is solved
// through the calibrated joint that links it to a found parent: given the parent's pose,
// a hinge leaves 1 degree of freedom and a ball 3 about a fixed centre, so 1 (hinge) or
// 2 (ball) labelled child markers determine the joint angles.
//
// Per frame (noexcept, allocation-free; all buffers are fixed-size members):
//  1. anchors: bodies found by identification. Points they use (and points sharing a blob
//     with those, the epipolar ghosts) are not available to the chain.
//  2. labelling, joint by joint from the roots (ChainModel::order()): each child marker's
//     candidates are the available points on its locus about the joint — the sphere of
//     its lever radius about the centre (ball), the circle about the axis (hinge) — within
//     gate_sigmas x its noise; with a recent angle of that joint (a prior, warm start) also
//     within the distance the marker can travel at max_angular_speed since the joint was
//     last solved (the gate grows with the time since it was last seen). A depth-first
//     search assigns distinct points to markers, consistent in their pairwise distances,
//     maximising the count; a marker labelled differently by two equally good assignments
//     is ambiguous and not used. Without a prior, 2 (hinge) or 3 (ball) labels are needed;
//     with one, 1 or 2.
//  3. initial angles: the prior, else closed form (hinge: the angle of the first label
//     about the axis; ball: Kabsch about the centre).
//  4. a Gauss-Newton solve of the joint angles of every chain-solved joint jointly, from
//     the anchors down, on all labelled markers weighted by their noise (point noise plus
//     the calibrated model's marker error), analytic Jacobians (rotation increments in the
//     parent's frame).
//  5. a chi-square test of the weighted residual (3 labels - dof degrees of freedom, at
//     `confidence`); on failure the worst marker is dropped and the solve repeated; a joint
//     left without enough markers is dropped with its descendants. Angles whose standard
//     deviation exceeds max_sd_deg are not published either. Never a wrong angle.
//  6. joints whose child was found by identification, the parent found or chain-solved
//     (chain_poses.cpp): the parent's pose predicts the joint centre (and a hinge's axis);
//     the child is refitted on its markers plus that evidence, each marker also tested
//     alone; a marker the joint exposes is dropped, a disagreement of the two poses makes
//     the angle invalid (inconsistent).
// A partial point's noise is derived from its image (the visible fraction of its most
// hidden view, marker_shape.h partial_centroid_shift), passed in by FrameProcessor.
// Every joint reports how it was solved (client::SolvedBy) and the standard deviation of
// its angles: from the chain solve's covariance, or, for joints whose two bodies were
// found, from the rigid fits' rotation covariances (sigma^2 (sum |r|^2 I - r r^T)^-1 per
// body, summed in the parent's frame).
// Capacity: up to kMaxBodies joints (kMaxChainDof = 96 degrees of freedom). The dense
// normal equations (two kMaxChainDof^2 matrices, ~144 KiB) live in a heap workspace
// allocated at create(); a frame touches only its active joints' ndof^2 block of them.
#pragma once

#include <Eigen/Cholesky>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "client/joints_message.h"
#include "identify/identify_types.h"
#include "track/chain_model.h"

namespace mocap {

namespace chain_detail {
inline constexpr int kMaxCandidates = 8;  // per marker; more make that marker ambiguous
// Workspace of the labelling search (chain_labeling.cpp).
struct LabelSearch {
  const MeasuredPoint* pts = nullptr;
  const std::vector<Vec3>* markers = nullptr;
  int k = 0;
  std::array<std::array<std::int16_t, kMaxCandidates>, kMaxMarkers> cand{};
  std::array<int, kMaxMarkers> cand_count{};
  std::array<double, kMaxPoints> tol_mm{};  // gate_sigmas x sigma of each point
  std::array<std::int16_t, kMaxMarkers> cur{};
  std::array<std::int16_t, kMaxMarkers> best{};
  std::array<bool, kMaxMarkers> agree{};
  int best_count = 0;
  int nodes = 0;
  int max_nodes = 0;
  bool hit_limit = false;
  bool pair_ok(int m, int p, int mm, int q) const noexcept;
  void visit(int m, int count) noexcept;
};

// Euler-angle (xyz) standard deviations of R_parent_child for a rotation-increment
// covariance in the parent's frame (rad^2).
std::array<double, 3> euler_sd(const Mat3& R, const Mat3& cov) noexcept;

// Fixed-capacity dense storage: resized per frame up to kMaxChainDof without allocating.
using DofMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxChainDof, kMaxChainDof>;
using DofVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxChainDof, 1>;
// The normal equations of the joint solve and their factorisation (gauss_newton()).
struct NormalEquations {
  DofMatrix H;
  DofVector g;
  Eigen::LDLT<DofMatrix> ldlt;
};
// A T on the heap with value semantics: allocated at construction (setup), deep-copied
// with its owner (setup code), never reallocated by the per-frame calls. A moved-from
// HeapValue may only be destroyed or assigned to.
template <typename T>
class HeapValue {
 public:
  HeapValue() : p_(std::make_unique<T>()) {}
  HeapValue(const HeapValue& o) : p_(o.p_ ? std::make_unique<T>(*o.p_) : std::make_unique<T>()) {}
  HeapValue& operator=(const HeapValue& o) {
    if (this == &o) return *this;
    if (!o.p_)
      p_ = std::make_unique<T>();
    else if (p_)
      *p_ = *o.p_;
    else
      p_ = std::make_unique<T>(*o.p_);
    return *this;
  }
  HeapValue(HeapValue&&) noexcept = default;
  HeapValue& operator=(HeapValue&&) noexcept = default;
  T& operator*() const noexcept { return *p_; }

 private:
  std::unique_ptr<T> p_;
};
}  // namespace chain_detail

struct ChainConfig {
  bool enabled = true;
  double point_sigma_mm = 0.2;    // per-coordinate noise of a whole marker (IdentifyConfig)
  double partial_sigma_mm = 1.0;  // of a partial marker (IdentifyConfig)
  // Per-coordinate error of a marker predicted through the calibrated chain: the joint
  // centre/axis estimates plus the parent's pose noise carried over the lever.
  double model_sigma_mm = 0.35;
  double gate_sigmas = 4.0;                     // locus and pairwise-distance gates, in sigmas
  double confidence = 0.9999;                   // chi-square test of a chain solution
  double max_angular_speed_deg_per_s = 1440.0;  // joint speed bound of the prior gate
  double max_prior_age_s = 0.25;                // an older last angle is no prior (cold start)
  double max_sd_deg = 1.0;                      // angles less certain than this are not published
  // Per-coordinate error of a calibrated joint centre (docs/evaluation.md measures
  // 0.02-0.09 mm): part of the centre test of joints whose child was found.
  double centre_sigma_mm = 0.1;
  // Per-component error (deg) of a calibrated hinge axis's direction, parent against child
  // (docs/evaluation.md measures 0.003-0.044 deg): part of the refit of a hinge's found child.
  double axis_sigma_deg = 0.05;
  int max_search_nodes = 4000;  // labelling search budget per joint and frame
};

struct ChainJointResult {
  client::SolvedBy solved_by = client::SolvedBy::kNone;
  std::array<double, 3> sd_rad{};  // of a0, a1, a2 (hinge: a0 only)
  // The child found, but the two poses disagree with the calibrated joint beyond the
  // noise (chain_poses.cpp): the angle is not valid.
  bool inconsistent = false;
};

// Result of one frame. Bodies solved by the chain get a pose (`chain_body`) and labels.
struct ChainResult {
  std::array<ChainJointResult, kMaxBodies> joints{};  // model order (joint_count used)
  std::array<bool, kMaxBodies> chain_body{};          // pose from the chain this frame
  // Found by identification, pose refitted with its joint centre (check_pose_joints).
  std::array<bool, kMaxBodies> refined_body{};
  std::array<Iso3, kMaxBodies> T_world_body{};  // valid where chain_body or refined_body
  std::array<std::array<std::int16_t, kMaxMarkers>, kMaxBodies> point_index_of_marker{};
  std::array<int, kMaxBodies> markers{};
  std::array<double, kMaxBodies> rms_mm{};
};

struct ChainCounters {
  std::uint64_t frames = 0;
  std::uint64_t attempts = 0;           // joints whose child was missing and parent anchored
  std::uint64_t joints_solved = 0;      // chain solutions published (per joint)
  std::uint64_t too_few_labels = 0;     // not enough unambiguous child markers
  std::uint64_t ambiguous_labels = 0;   // markers left unlabelled as ambiguous
  std::uint64_t chi2_drops = 0;         // markers dropped by the chi-square test
  std::uint64_t chi2_rejects = 0;       // joints dropped (test failed with too few markers)
  std::uint64_t uncertain_rejects = 0;  // joints dropped for sd > max_sd_deg
  std::uint64_t node_limit_hits = 0;
  std::uint64_t pose_refits = 0;   // found children of ball joints refitted with the centre
  std::uint64_t pose_rejects = 0;  // found children whose poses disagree with the joint
  // Coverage: frames in which joint j (model order) was valid, by how it was solved.
  std::array<std::uint64_t, kMaxBodies> joint_poses{};
  std::array<std::uint64_t, kMaxBodies> joint_chain{};
};

class ChainSolver {
 public:
  static Expected<ChainSolver> create(ChainModel model, const ChainConfig& config);

  // pts[0..n): this frame's points; poses: identification's result (bodies found are the
  // anchors; read only). Fills `out` for every joint of the model. partial_sigma_mm
  // (optional, n entries): the per-coordinate noise of each partial point, derived from
  // its image (FrameProcessor::measure_points, marker_shape.h); without it a
  // partial point has the configured partial_sigma_mm. Never below point_sigma_mm.
  void solve(const MeasuredPoint* pts, int n, std::int64_t timestamp_ns, const BodyPoses& poses,
             ChainResult& out, const double* partial_sigma_mm = nullptr) noexcept;
  // Remembers the relative rotation of every joint valid this frame (the priors of the
  // next frame): call with the final poses (identified and chain-solved).
  void remember(const BodyPoses& poses, std::int64_t timestamp_ns) noexcept;
  void reset() noexcept;

  const ChainModel& model() const noexcept { return model_; }
  const ChainCounters& counters() const noexcept { return counters_; }

 private:
  struct Prior {
    bool valid = false;
    Mat3 R_parent_child = Mat3::Identity();
    std::int64_t t_ns = 0;
  };
  ChainSolver(ChainModel model, const ChainConfig& config);
  int label_child(int j, const Iso3& T_world_parent, const MeasuredPoint* pts, int n,
                  std::int64_t t_ns, std::array<std::int16_t, kMaxMarkers>& labels) noexcept;
  bool initial_rotation(int j, const Iso3& T_world_parent, const MeasuredPoint* pts,
                        const std::array<std::int16_t, kMaxMarkers>& labels, std::int64_t t_ns,
                        Mat3& R) const noexcept;
  // Gauss-Newton over the chain joints in `active`; false when the normal equations are
  // singular. Fills the covariance diagonal blocks and the weighted sum of squares.
  bool gauss_newton(const MeasuredPoint* pts, const BodyPoses& poses, ChainResult& out) noexcept;
  void forward(const BodyPoses& poses, ChainResult& out) const noexcept;
  // Standard deviations of an active joint's angles (from the solve's covariance).
  std::array<double, 3> active_sd(int j) const noexcept;
  // Takes joint j out of this frame's chain solution, with every joint below it.
  void deactivate(int j, ChainResult& out) noexcept;
  // World-frame rotation covariance of a body's pose (rad^2): rigid fit or chain.
  Mat3 body_cov(int b, const BodyPoses& poses, const ChainResult& out) const noexcept;
  // Per-coordinate variance of point p (index in this frame's points): its noise plus the
  // model's marker error.
  double sigma_sq(int p, const MeasuredPoint& pt) const noexcept;
  // The same without the model's error: point p measured as a marker of a body whose own
  // pose is fitted (the refit of a found child, chain_poses.cpp).
  double point_sigma_sq(int p, const MeasuredPoint& pt) const noexcept;
  // Joints whose child was found (chain_poses.cpp): ball refit with the joint centre, centre
  // test, standard deviations.
  void check_pose_joints(const MeasuredPoint* pts, int n, const BodyPoses& poses,
                         ChainResult& out) noexcept;
  // What the parent's pose says about a found child's pose (chain_poses.cpp): the joint
  // centre c_w (covariance cov_c, weight W_c = cov_c^-1) and, for a hinge, the axis:
  // the child's axis has no component along U (the two directions across the parent's
  // axis; covariance cov_a, weight W_a).
  struct JointEvidence {
    Vec3 c_w = Vec3::Zero();
    Mat3 cov_c = Mat3::Identity();
    Mat3 W_c = Mat3::Identity();
    bool hinge = false;
    Eigen::Matrix<double, 3, 2> U = Eigen::Matrix<double, 3, 2>::Zero();
    Eigen::Matrix2d cov_a = Eigen::Matrix2d::Identity();
    Eigen::Matrix2d W_a = Eigen::Matrix2d::Identity();
  };
  // Joint j's found child refitted on its labels plus the joint's evidence, dropping its
  // worst marker while the chi-square tests fail; false: inconsistent.
  bool refit_child(int j, const JointEvidence& ev, const MeasuredPoint* pts, int n,
                   const BodyPose& child, std::array<std::int16_t, kMaxMarkers>& labels, Iso3& T_wc,
                   Mat3& cov_R) const noexcept;
  // Covariance (mm^2, world) of the joint centre c_world as placed by body b's pose.
  Mat3 centre_cov(int b, const Vec3& c_world, const BodyPoses& poses,
                  const ChainResult& out) const noexcept;

  ChainModel model_;
  ChainConfig config_;
  double max_rate_rad_per_s_ = 0.0;
  std::vector<Prior> priors_;  // per joint
  // Per-frame workspace.
  std::array<bool, kMaxPoints> available_{};
  std::array<bool, kMaxBodies> active_{};     // chain joint being solved, by joint index
  std::array<bool, kMaxBodies> warm_{};       // its labels used a prior
  std::array<Mat3, kMaxBodies> R_rel_{};      // by joint index
  std::array<int, kMaxBodies> dof_offset_{};  // by joint index
  std::array<double, kMaxChainDof> sd_dof_{};
  const double* partial_sigma_mm_ = nullptr;  // this frame's (solve()), or null
  int partial_sigma_count_ = 0;
  double chi2_ = 0.0;
  int residual_markers_ = 0;
  int dof_ = 0;
  std::array<Mat3, kMaxBodies> cov_{};          // ball: 3x3 covariance of the increment
  std::array<Mat3, kMaxBodies> refined_cov_{};  // by body: world rotation cov of a refit
  // gauss_newton()'s normal equations (~146 KiB: heap, allocated with the solver)
  chain_detail::HeapValue<chain_detail::NormalEquations> normal_;
  chain_detail::LabelSearch search_;
  ChainCounters counters_;
};

}  // namespace mocap
