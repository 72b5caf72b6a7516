// Design: see stereo_triangulator.h. Why the plane-angle window is exact: let r be the
// unit ray of blob i (camera a) and theta its epipolar plane angle about the baseline,
// rho = |r x baseline_dir| its distance from the baseline direction. The plane of
// another blob at angle theta' makes the angle phi with r, sin(phi) = rho |sin(theta -
// theta')|. In undistorted pixels the distance of blob i to that epipolar line is at
// least min(fx, fy) * sin(phi) (normalised distance >= sin(phi) since |(x, y, 1)| >= 1).
// So d_a <= tol implies |sin(theta - theta')| <= tol / (min(fx, fy) * rho): with theta
// taken modulo pi, a window of half-width asin(that) around theta contains every pair
// within tolerance; the exact symmetric test then decides. The angles are compared as
// pseudo-angles (plane_key, monotone in theta), the window's ends found by turning the
// plane's direction by that half-width (its sine and cosine: no trigonometric call).
#include "stereo/stereo_triangulator.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/mat3_product.h"

namespace mocap {
namespace {

bool finite(double v) { return std::isfinite(v); }

// The plane of direction (p, q) about the baseline, taken modulo pi (a plane, not a
// half-plane), as a pseudo-angle in [0, 2): q / (p + q) over [0, pi/2], 1 + |p| / (|p| +
// q) over (pi/2, pi) after folding q >= 0; monotone in the angle, so it sorts and bounds
// windows exactly as the angle does. The zero vector (a ray along the baseline) is 0.
double plane_key(double p, double q) noexcept {
  if (q < 0.0 || (q == 0.0 && p < 0.0)) {
    p = -p;
    q = -q;
  }
  const double sum = std::abs(p) + q;
  if (!(sum > 0.0)) return 0.0;
  return p >= 0.0 ? q / sum : 1.0 + -p / sum;
}

}  // namespace

Expected<StereoTriangulator> StereoTriangulator::create(const Rig& rig, const StereoConfig& c,
                                                        int cam_a, int cam_b) {
  const auto n_cams = static_cast<int>(rig.cameras.size());
  if (cam_a < 0 || cam_b < 0 || cam_a >= n_cams || cam_b >= n_cams || cam_a == cam_b ||
      cam_a >= kMaxCameras || cam_b >= kMaxCameras)
    return make_error("stereo", "cameras",
                      "pair (" + std::to_string(cam_a) + ", " + std::to_string(cam_b) +
                          ") invalid for a rig of " + std::to_string(n_cams) + " cameras");
  if (!(finite(c.epipolar_tolerance_px) && c.epipolar_tolerance_px > 0.0))
    return make_error("stereo", "epipolar_tolerance_px", "must be a positive number");
  if (!(finite(c.max_reproj_px) && c.max_reproj_px > 0.0))
    return make_error("stereo", "max_reproj_px", "must be a positive number");
  if (!(finite(c.min_depth_mm) && c.min_depth_mm >= 0.0))
    return make_error("stereo", "min_depth_mm", "must be a non-negative number");
  if (!(finite(c.max_depth_mm) && c.max_depth_mm > c.min_depth_mm))
    return make_error("stereo", "max_depth_mm", "must be a number above min_depth_mm");
  if (c.max_points_per_camera < 1 || c.max_points_per_camera > 32767)
    return make_error("stereo", "max_points_per_camera", "must be in [1, 32767]");
  if (c.max_candidates < 1) return make_error("stereo", "max_candidates", "must be >= 1");

  const CameraModel& ca = rig.cameras[static_cast<std::size_t>(cam_a)];
  const CameraModel& cb = rig.cameras[static_cast<std::size_t>(cam_b)];
  auto geometry = make_stereo_geometry(ca, cb);
  if (!geometry) return geometry.error();

  StereoTriangulator t;
  t.config_ = c;
  t.cam_a_model_ = ca;
  t.cam_b_model_ = cb;
  t.geometry_ = *geometry;
  t.cam_a_ = cam_a;
  t.cam_b_ = cam_b;
  // Any unit vector not parallel to the baseline seeds the perpendicular pair.
  const Vec3& bdir = t.geometry_.baseline_dir_0;
  Vec3 seed = Vec3::UnitX();
  if (std::abs(bdir.x()) > 0.9) seed = Vec3::UnitY();
  t.plane_u_0_ = bdir.cross(seed).normalized();
  t.plane_v_0_ = bdir.cross(t.plane_u_0_);
  t.plane_u_1_ = t.geometry_.R_10 * t.plane_u_0_;
  t.plane_v_1_ = t.geometry_.R_10 * t.plane_v_0_;
  auto ua = BlobUndistorter::create(ca, c.max_points_per_camera);
  auto ub = BlobUndistorter::create(cb, c.max_points_per_camera);
  if (!ua) return ua.error();
  if (!ub) return ub.error();
  t.undistort_a_ = std::move(ua).value();
  t.undistort_b_ = std::move(ub).value();
  const auto cap = static_cast<std::size_t>(c.max_points_per_camera);
  t.obs_a_.resize(cap);
  t.obs_b_.resize(cap);
  t.keys_b_.resize(cap);
  t.keys_b_open_.resize(cap);
  t.use_a_.assign(cap, 0);
  t.use_b_.assign(cap, 0);
  return t;
}

void StereoTriangulator::prepare(const UndistortedBlobs& blobs, int n, int camera,
                                 std::vector<Observation>& obs, const int* skip) noexcept {
  const CameraModel& cam = camera == 0 ? cam_a_model_ : cam_b_model_;
  const double f_min = std::min(cam.fx, cam.fy);
  for (int i = 0; i < n; ++i) {
    Observation& o = obs[static_cast<std::size_t>(i)];
    o.px = blobs.px[i];
    o.valid = false;
    o.key = 0.0;
    o.whole = true;
    if (blobs.valid[i] == 0) {  // not finite, or the undistortion failed
      ++counters_.undistort_failed[static_cast<std::size_t>(camera)];
      continue;
    }
    const Vec2& xn = blobs.xn[i];
    o.valid = true;
    if (skip != nullptr && skip[i] >= 0) continue;
    o.s = to_scaled(cam, xn);
    // The ray in camera-a coordinates (its length does not change the plane).
    Vec3 r(xn.x(), xn.y(), 1.0);
    if (camera == 1) {  // camera b's blobs are only searched: no window
      // (R_10^T r).u = r.(R_10 u): the pair's plane basis turned into camera b once.
      o.key = plane_key(r.dot(plane_u_1_), r.dot(plane_v_1_));
      continue;
    }
    // Camera a's own key is never compared (only camera b's are searched): not computed.
    r.normalize();
    const double p = r.dot(plane_u_0_);
    const double q = r.dot(plane_v_0_);
    // |(p, q)| <= 1 (a unit ray): no overflow or underflow to guard against (std::hypot's
    // care), and the window's margins cover far more than its last-bit rounding.
    const double rho = std::sqrt(p * p + q * q);
    // Safety margins for rounding: the window only has to be conservative (its sine
    // widened, and once more for the rotation and the keys' own rounding).
    const double s = config_.epipolar_tolerance_px * (1.0 + 1e-9) / (f_min * rho) + 1e-12;
    const double sw = s * (1.0 + 1e-9) + 1e-12;
    if (!(sw < 1.0) || !finite(sw)) continue;  // the whole pencil
    o.whole = false;
    // The window's ends: the plane's direction (p, q) / rho turned by -w and +w, sin w = sw.
    const double cw = std::sqrt(1.0 - sw * sw);
    const double up = p / rho, uq = q / rho;
    o.lo = plane_key(up * cw + uq * sw, uq * cw - up * sw);
    o.hi = plane_key(up * cw - uq * sw, uq * cw + up * sw);
  }
}

void StereoTriangulator::try_pair(int i, int j, PointList& out, int capacity) noexcept {
  const Observation& a = obs_a_[static_cast<std::size_t>(i)];
  const Observation& b = obs_b_[static_cast<std::size_t>(j)];
  double d_a = 0.0, d_b = 0.0;
  epipolar_distances_px(geometry_, a.s, b.s, d_a, d_b);
  const double tol = config_.epipolar_tolerance_px;
  if (!(d_a <= tol && d_b <= tol)) return;
  ++counters_.pairs_in_tolerance;

  Vec2 sa_c, sb_c;
  niter2_correct(geometry_.F_s, a.s, b.s, sa_c, sb_c);
  Vec3 X_a;
  if (!intersect_rays(geometry_, from_scaled(cam_a_model_, sa_c), from_scaled(cam_b_model_, sb_c),
                      X_a)) {
    ++counters_.rejected_degenerate;
    return;
  }
  const double z_a = X_a.z();
  const double z_b = mul(geometry_.R_10, X_a).z() + geometry_.t_10.z();
  if (!(z_a > 0.0 && z_b > 0.0)) {
    ++counters_.rejected_cheirality;
    return;
  }
  const double lo = config_.min_depth_mm, hi = config_.max_depth_mm;
  if (!(z_a >= lo && z_a <= hi && z_b >= lo && z_b <= hi)) {
    ++counters_.rejected_depth;
    return;
  }
  const Vec3 X_world = mul_transposed(geometry_.R_0w, X_a - geometry_.t_0w);
  double rms_px = 0.0;
  if (!reprojection_rms_px(cam_a_model_, cam_b_model_, X_world, a.px, b.px, rms_px)) {
    ++counters_.rejected_cheirality;
    return;
  }
  if (!(rms_px <= config_.max_reproj_px)) {
    ++counters_.rejected_reproj;
    return;
  }
  ++counters_.candidates;
  // Counted even when dropped, so the ambiguity flags of emitted ones stay truthful.
  ++use_a_[static_cast<std::size_t>(i)];
  ++use_b_[static_cast<std::size_t>(j)];
  if (out.size() >= capacity) {
    ++counters_.candidate_overflow;
    frame_overflow_ = true;
    return;
  }
  Point3 p;
  p.X_world = X_world;
  p.reproj_px = rms_px;
  p.epipolar_px = std::max(d_a, d_b);
  p.blob_index[static_cast<std::size_t>(cam_a_)] = static_cast<std::int16_t>(i);
  p.blob_index[static_cast<std::size_t>(cam_b_)] = static_cast<std::int16_t>(j);
  out.push_back(p);
}

void StereoTriangulator::scan_range(int i, const SortKey* keys, int n, double lo, double hi,
                                    PointList& out, int capacity) noexcept {
  const SortKey* first = keys;
  const SortKey* last = first + n;
  const SortKey* it =
      std::lower_bound(first, last, lo, [](const SortKey& k, double v) { return k.key < v; });
  for (; it != last && it->key <= hi; ++it) try_pair(i, it->index, out, capacity);
}

bool StereoTriangulator::process(const Vec2* px_a, int n_a, const Vec2* px_b, int n_b,
                                 PointList& out, SettledBlobs settled) noexcept {
  const bool bad =
      n_a < 0 || n_b < 0 || (n_a > 0 && px_a == nullptr) || (n_b > 0 && px_b == nullptr);
  // Bad input undistorts nothing; the view form counts it.
  return process(bad ? UndistortedBlobs{px_a, n_a} : undistort_a_.undistort(px_a, n_a),
                 bad ? UndistortedBlobs{px_b, n_b} : undistort_b_.undistort(px_b, n_b), out,
                 settled);
}

bool StereoTriangulator::process(const UndistortedBlobs& a, const UndistortedBlobs& b,
                                 PointList& out, SettledBlobs settled) noexcept {
  out.clear();
  settled_ = settled.a != nullptr && settled.b != nullptr ? settled : SettledBlobs{};
  ++counters_.frames;
  frame_overflow_ = false;
  const int r_a = a.received, r_b = b.received;
  if (r_a < 0 || r_b < 0 || (r_a > 0 && a.px == nullptr) || (r_b > 0 && b.px == nullptr)) {
    ++counters_.bad_input;
    return false;
  }
  counters_.points_in[0] += static_cast<std::uint64_t>(r_a);
  counters_.points_in[1] += static_cast<std::uint64_t>(r_b);
  const int cap = config_.max_points_per_camera;
  // Blobs beyond this pair's capacity, or not undistorted by the view's, are ignored.
  const int n_a = std::min({r_a, cap, a.count});
  const int n_b = std::min({r_b, cap, b.count});
  if (n_a < r_a) {
    counters_.points_overflow[0] += static_cast<std::uint64_t>(r_a - n_a);
    frame_overflow_ = true;
  }
  if (n_b < r_b) {
    counters_.points_overflow[1] += static_cast<std::uint64_t>(r_b - n_b);
    frame_overflow_ = true;
  }
  prepare(b, n_b, 1, obs_b_);
  std::fill_n(use_a_.begin(), n_a, std::uint16_t{0});
  std::fill_n(use_b_.begin(), n_b, std::uint16_t{0});
  const int capacity = std::min(out.capacity(), config_.max_candidates);

  // A settled a-blob pairs only with unsettled b-blobs: two settled blobs are no candidate.
  const auto settled_a = [&](int i) noexcept {
    return settled_.a != nullptr && settled_.a[i] >= 0;
  };
  if (config_.method == MatchMethod::kExhaustive) {
    prepare(a, n_a, 0, obs_a_);
    for (int i = 0; i < n_a; ++i) {
      if (!obs_a_[static_cast<std::size_t>(i)].valid) continue;
      const bool open_only = settled_a(i);
      counters_.settled_blobs += open_only ? 1u : 0u;
      for (int j = 0; j < n_b; ++j)
        if (obs_b_[static_cast<std::size_t>(j)].valid && !(open_only && settled_.b[j] >= 0))
          try_pair(i, j, out, capacity);
    }
  } else {
    int k = 0;
    for (int j = 0; j < n_b; ++j) {
      const Observation& o = obs_b_[static_cast<std::size_t>(j)];
      if (o.valid) keys_b_[static_cast<std::size_t>(k++)] = SortKey{o.key, j};
    }
    std::sort(keys_b_.begin(), keys_b_.begin() + k,
              [](const SortKey& x, const SortKey& y) { return x.key < y.key; });
    // The settled a-blobs search the unsettled b-blobs' keys (in the same order).
    int k_open = 0;
    if (settled_.a != nullptr)
      for (int r = 0; r < k; ++r)
        if (settled_.b[keys_b_[static_cast<std::size_t>(r)].index] < 0)
          keys_b_open_[static_cast<std::size_t>(k_open++)] = keys_b_[static_cast<std::size_t>(r)];
    // With no unsettled b-blob, a settled a-blob searches nothing: no window for it.
    prepare(a, n_a, 0, obs_a_, k_open == 0 ? settled_.a : nullptr);
    for (int i = 0; i < n_a; ++i) {
      const Observation& o = obs_a_[static_cast<std::size_t>(i)];
      if (!o.valid) continue;
      const SortKey* keys = keys_b_.data();
      int n = k;
      if (settled_a(i)) {
        ++counters_.settled_blobs;
        keys = keys_b_open_.data();
        n = k_open;
        if (n == 0) continue;
      }
      if (o.whole) {
        scan_range(i, keys, n, -1.0, 4.0, out, capacity);  // the whole pencil
      } else if (o.lo > o.hi) {  // through 0 (= pi): both ends of the keys
        scan_range(i, keys, n, 0.0, o.hi, out, capacity);
        scan_range(i, keys, n, o.lo, 2.0, out, capacity);
      } else {
        scan_range(i, keys, n, o.lo, o.hi, out, capacity);
      }
    }
  }

  for (Point3& p : out) {
    const auto i = static_cast<std::size_t>(p.blob_index[static_cast<std::size_t>(cam_a_)]);
    const auto j = static_cast<std::size_t>(p.blob_index[static_cast<std::size_t>(cam_b_)]);
    p.ambiguous = use_a_[i] > 1 || use_b_[j] > 1;
    p.reported = !p.ambiguous;
    if (p.ambiguous) ++counters_.ambiguous;
  }
  return !frame_overflow_;
}

}  // namespace mocap
