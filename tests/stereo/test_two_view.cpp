// Tests of optimal two-view triangulation (niter2), the DLT and the N-view building
// blocks. The optimality test is independent of the code under test: it searches the
// pencil of epipolar planes (planes through both optical centres, built here from the
// camera centres in the world frame), parameterised by an angle; for each plane it
// takes the closest points on the two epipolar lines (pixel-scaled undistorted
// coordinates) and minimises the sum of squared distances by a fine grid search plus
// golden-section refinement. niter2's corrected points must equal that optimum to
// 1e-6 px, including near-degenerate geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "stereo/nview.h"
#include "stereo/two_view.h"
#include "tests/stereo/stereo_test_rig.h"

namespace mocap {
namespace {

struct PencilOptimum {
  Vec2 s0c, s1c;
  double cost;
};

// The search runs in long double: the cost's rounding noise limits how well golden
// section can locate the minimum (position error ~ sqrt(noise)), and the extra bits
// keep the reference two orders of magnitude below the 1e-6 px acceptance.
class EpipolarPencil {
 public:
  using Real = long double;
  EpipolarPencil(const CameraModel& c0, const CameraModel& c1) : c0_(c0), c1_(c1) {
    const Vec3 b = (c1.center_world() - c0.center_world()).normalized();
    const Vec3 seed = std::abs(b.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    u_ = b.cross(seed).normalized();
    v_ = b.cross(u_);
  }

  // Squared distance from s to the epipolar line of the plane with world normal n in
  // camera c, and the closest point on the line.
  static Real foot(const CameraModel& c, const Real n_world[3], const Vec2& s, Real s_on[2]) {
    Real n[3];
    for (int r = 0; r < 3; ++r) {  // the plane passes through the centre: n_cam = R n
      n[r] = 0.0L;
      for (int k = 0; k < 3; ++k) n[r] += static_cast<Real>(c.R_cam_world(r, k)) * n_world[k];
    }
    const Real l0 = n[0] / static_cast<Real>(c.fx), l1 = n[1] / static_cast<Real>(c.fy);
    const Real norm2 = l0 * l0 + l1 * l1;
    const Real sx = static_cast<Real>(s.x()), sy = static_cast<Real>(s.y());
    const Real r = l0 * sx + l1 * sy + n[2];
    s_on[0] = sx - r / norm2 * l0;
    s_on[1] = sy - r / norm2 * l1;
    return r * r / norm2;
  }

  Real cost(Real theta, const Vec2& s0, const Vec2& s1, Real f0[2], Real f1[2]) const {
    Real n[3];
    for (int k = 0; k < 3; ++k)
      n[k] =
          std::cos(theta) * static_cast<Real>(u_[k]) + std::sin(theta) * static_cast<Real>(v_[k]);
    return foot(c0_, n, s0, f0) + foot(c1_, n, s1, f1);
  }
  Real cost(Real theta, const Vec2& s0, const Vec2& s1) const {
    Real a[2], b[2];
    return cost(theta, s0, s1, a, b);
  }

  PencilOptimum minimise(const Vec2& s0, const Vec2& s1) const {
    constexpr int kGrid = 8000;
    const Real step = std::numbers::pi_v<Real> / kGrid;
    int best = 0;
    Real best_cost = HUGE_VALL;
    for (int i = 0; i < kGrid; ++i) {
      const Real c = cost(i * step, s0, s1);
      if (c < best_cost) {
        best_cost = c;
        best = i;
      }
    }
    // Golden section on the bracket around the best grid angle.
    const Real gr = (std::sqrt(5.0L) - 1.0L) / 2.0L;
    Real a = (best - 1) * step, b = (best + 1) * step;
    Real x1 = b - gr * (b - a), x2 = a + gr * (b - a);
    Real f1 = cost(x1, s0, s1), f2 = cost(x2, s0, s1);
    for (int it = 0; it < 300 && b - a > 1e-19L; ++it) {
      if (f1 < f2) {
        b = x2;
        x2 = x1;
        f2 = f1;
        x1 = b - gr * (b - a);
        f1 = cost(x1, s0, s1);
      } else {
        a = x1;
        x1 = x2;
        f1 = f2;
        x2 = a + gr * (b - a);
        f2 = cost(x2, s0, s1);
      }
    }
    Real p0[2], p1[2];
    PencilOptimum o;
    o.cost = static_cast<double>(cost(0.5L * (a + b), s0, s1, p0, p1));
    o.s0c = Vec2(static_cast<double>(p0[0]), static_cast<double>(p0[1]));
    o.s1c = Vec2(static_cast<double>(p1[0]), static_cast<double>(p1[1]));
    return o;
  }

 private:
  const CameraModel& c0_;
  const CameraModel& c1_;
  Vec3 u_, v_;
};

// Pixel-scaled undistorted coordinates of an observed pixel.
Vec2 scaled_of_pixel(const CameraModel& c, const Vec2& px) {
  Vec2 xn;
  EXPECT_TRUE(undistort_pixel(c, px, xn));
  return to_scaled(c, xn);
}

// niter2 vs the pencil search for one observation pair; returns the worst deviation.
double niter2_vs_pencil(const StereoGeometry& g, const EpipolarPencil& pencil, const Vec2& s0,
                        const Vec2& s1, int polish) {
  Vec2 s0c, s1c;
  niter2_correct(g.F_s, s0, s1, s0c, s1c, polish);
  const PencilOptimum opt = pencil.minimise(s0, s1);
  return std::max((s0c - opt.s0c).norm(), (s1c - opt.s1c).norm());
}

// polish = 0: the paper's niter2 alone; default: with the convergence polish.
void expect_optimal(const Rig& rig, std::mt19937& rng, const std::vector<Vec3>& points,
                    double noise_px, const char* label, int polish = 10) {
  const auto& c0 = rig.cameras[0];
  const auto& c1 = rig.cameras[1];
  const StereoGeometry g = make_stereo_geometry(c0, c1).value();
  const EpipolarPencil pencil(c0, c1);
  std::normal_distribution<double> noise(0.0, noise_px);
  double worst = 0.0;
  for (const Vec3& X : points) {
    Vec2 px0, px1;
    ASSERT_TRUE(project(c0, X, px0) && project(c1, X, px1)) << label;
    px0 += Vec2(noise(rng), noise(rng));
    px1 += Vec2(noise(rng), noise(rng));
    worst = std::max(worst, niter2_vs_pencil(g, pencil, scaled_of_pixel(c0, px0),
                                             scaled_of_pixel(c1, px1), polish));
  }
  EXPECT_LT(worst, 1e-6) << label;
  std::printf("[ info ] %s (polish %d): worst deviation from the pencil optimum %.2e px\n", label,
              polish, worst);
}

TEST(TwoView, Niter2EqualsPencilOptimumInTheWorkingVolume) {
  const Rig rig = test::paper_rig();
  std::mt19937 rng(1);
  std::vector<Vec3> pts;
  for (int i = 0; i < 60; ++i) {
    Vec2 a, b;
    pts.push_back(test::random_visible_point(rig, rng, a, b));
  }
  expect_optimal(rig, rng, pts, 0.5, "noise 0.5 px");
  expect_optimal(rig, rng, pts, 2.0, "noise 2 px");
  // In ordinary geometry the paper's two steps alone already reach the optimum.
  expect_optimal(rig, rng, pts, 0.5, "noise 0.5 px, niter2 alone", 0);
}

TEST(TwoView, Niter2EqualsPencilOptimumNearTheBaselineDirection) {
  // Forward-moving pair: camera 1 sits 400 mm ahead of camera 0, so both epipoles are
  // inside the images and points close to the baseline line image near them.
  Rig rig;
  rig.cameras.push_back(test::look_at_camera("c0", Vec3(0, 0, 0), Vec3(0, 0, 3000), 1290.0,
                                             {-0.12, 0.09, 0.0, 0.0, 0.0}));
  rig.cameras.push_back(test::look_at_camera("c1", Vec3(20, 10, 400), Vec3(60, -20, 3000), 1290.0,
                                             {-0.1, 0.05, 0.0, 0.0, 0.0}));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> lam(2.0, 8.0), off(-15.0, 15.0);
  const Vec3 C0 = rig.cameras[0].center_world(), C1 = rig.cameras[1].center_world();
  std::vector<Vec3> pts;
  for (int i = 0; i < 100; ++i)
    pts.push_back(C0 + lam(rng) * (C1 - C0) + Vec3(off(rng), off(rng), 0.0));
  expect_optimal(rig, rng, pts, 0.5, "near baseline");
}

TEST(TwoView, Niter2EqualsPencilOptimumForDistantPoints) {
  const Rig rig = test::paper_rig();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-0.3, 0.3), uz(1e4, 1e7);
  std::vector<Vec3> pts;
  for (int i = 0; i < 100; ++i) {
    const double z = uz(rng);
    pts.push_back(Vec3(ux(rng) * z, ux(rng) * z, z));
  }
  expect_optimal(rig, rng, pts, 0.5, "distant");
}

TEST(TwoView, Niter2EqualsPencilOptimumForTinyBaseline) {
  const Rig rig = test::paper_rig(1.0);  // 1 mm baseline
  std::mt19937 rng(4);
  std::vector<Vec3> pts;
  for (int i = 0; i < 100; ++i) {
    Vec2 a, b;
    pts.push_back(test::random_visible_point(rig, rng, a, b));
  }
  expect_optimal(rig, rng, pts, 0.5, "tiny baseline");
}

TEST(TwoView, RoundTripTriangulateProject) {
  const Rig rig = test::paper_rig();
  const auto& c0 = rig.cameras[0];
  const auto& c1 = rig.cameras[1];
  const StereoGeometry g = make_stereo_geometry(c0, c1).value();
  std::mt19937 rng(5);
  for (int i = 0; i < 2000; ++i) {
    Vec2 px0, px1, xn0, xn1;
    const Vec3 X = test::random_visible_point(rig, rng, px0, px1, 400.0, 3000.0);
    ASSERT_TRUE(undistort_pixel(c0, px0, xn0) && undistort_pixel(c1, px1, xn1));
    Vec3 Xn, Xd, Xc;
    ASSERT_TRUE(triangulate_niter2(g, xn0, xn1, Xn));
    ASSERT_TRUE(triangulate_dlt(g, xn0, xn1, Xd));
    ASSERT_TRUE(triangulate_niter2(c0, c1, xn0, xn1, Xc));
    EXPECT_LT((Xn - X).norm(), 1e-7 * X.norm());
    EXPECT_LT((Xd - X).norm(), 1e-7 * X.norm());
    EXPECT_EQ(Xn, Xc);
    double rms = 1.0;
    ASSERT_TRUE(reprojection_rms_px(c0, c1, Xn, px0, px1, rms));
    EXPECT_LT(rms, 1e-8);
    Vec3 Xp;
    double reproj = 1.0;
    ASSERT_TRUE(triangulate_pixels(g, c0, c1, px0, px1, Xp, reproj));
    EXPECT_LT((Xp - X).norm(), 1e-7 * X.norm());
    EXPECT_LT(reproj, 1e-8);
    // A known pixel offset shows up in the RMS: (3, 4) px in view 0 only -> 5/sqrt(2).
    ASSERT_TRUE(reprojection_rms_px(c0, c1, X, px0 + Vec2(3.0, 4.0), px1, rms));
    EXPECT_NEAR(rms, 5.0 / std::sqrt(2.0), 1e-9);
  }
}

TEST(TwoView, NoiseAtOneMetreGivesSubTenthMillimetreError) {
  // The paper's rig; 0.03 px Gaussian noise per coordinate on points around 1 m.
  const Rig rig = test::paper_rig();
  const auto& c0 = rig.cameras[0];
  const auto& c1 = rig.cameras[1];
  const StereoGeometry g = make_stereo_geometry(c0, c1).value();
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, 0.03);
  double sq = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    Vec2 px0, px1, xn0, xn1;
    const Vec3 X = test::random_visible_point(rig, rng, px0, px1, 900.0, 1100.0);
    px0 += Vec2(noise(rng), noise(rng));
    px1 += Vec2(noise(rng), noise(rng));
    ASSERT_TRUE(undistort_pixel(c0, px0, xn0) && undistort_pixel(c1, px1, xn1));
    Vec3 Xh;
    ASSERT_TRUE(triangulate_niter2(g, xn0, xn1, Xh));
    sq += (Xh - X).squaredNorm();
  }
  const double rmse_mm = std::sqrt(sq / n);
  std::printf("[ info ] 0.03 px noise at 1 m: 3D RMSE %.4f mm\n", rmse_mm);
  EXPECT_LT(rmse_mm, 0.1);
  EXPECT_GT(rmse_mm, 0.005);  // the noise really reached the estimate
}

TEST(TwoView, PointBehindBothCamerasIsRejected) {
  const Rig rig = test::paper_rig();
  const StereoGeometry g = make_stereo_geometry(rig.cameras[0], rig.cameras[1]).value();
  // Mirror images of a point behind the rig: the rays' back-projections meet at z < 0.
  const Vec3 X(30.0, -20.0, -900.0);
  const Vec3 Xc0 = rig.cameras[0].R_cam_world * X + rig.cameras[0].t_cam_world;
  const Vec3 Xc1 = rig.cameras[1].R_cam_world * X + rig.cameras[1].t_cam_world;
  ASSERT_LT(Xc0.z(), 0.0);
  ASSERT_LT(Xc1.z(), 0.0);
  const Vec2 xn0 = Xc0.head<2>() / Xc0.z(), xn1 = Xc1.head<2>() / Xc1.z();
  Vec3 out(1, 2, 3);
  EXPECT_FALSE(triangulate_niter2(g, xn0, xn1, out));
  EXPECT_FALSE(triangulate_dlt(g, xn0, xn1, out));
  EXPECT_EQ(out, Vec3(1, 2, 3));
}

TEST(TwoView, ZeroBaselineIsASetupError) {
  Rig rig = test::paper_rig();
  rig.cameras[1].t_cam_world = -rig.cameras[1].R_cam_world * rig.cameras[0].center_world();
  const auto g = make_stereo_geometry(rig.cameras[0], rig.cameras[1]);
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(g.error().message,
            "stereo: cam0/cam1: zero baseline (the two optical centres coincide)");
}

TEST(NView, LinearAndGaussNewtonRecoverThePoint) {
  Rig rig = test::paper_rig();
  rig.cameras.push_back(test::look_at_camera("cam2", Vec3(0.0, -400.0, 100.0),
                                             Vec3(0.0, 0.0, 1000.0), 1100.0,
                                             {-0.2, 0.1, 0.002, -0.003, 0.05}));
  // (Every distortion term, tangential and k3 included: Gauss-Newton's own Jacobian must
  // agree with project()'s, which the gradient check below uses.)
  const CameraModel* cams[3] = {&rig.cameras[0], &rig.cameras[1], &rig.cameras[2]};
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (int i = 0; i < 300; ++i) {
    Vec2 px[3], xn[3];
    const Vec3 X = test::random_visible_point(rig, rng, px[0], px[1], 800.0, 1200.0);
    ASSERT_TRUE(project(*cams[2], X, px[2]));
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(undistort_pixel(*cams[k], px[k], xn[k]));
    Vec3 Xl;
    ASSERT_TRUE(triangulate_linear_nview(cams, xn, 3, Xl));
    EXPECT_LT((Xl - X).norm(), 1e-7 * X.norm());
    // With noise, Gauss-Newton must reach a stationary point of the pixel error that
    // is no worse than the linear start.
    Vec2 noisy[3];
    for (int k = 0; k < 3; ++k) {
      noisy[k] = px[k] + Vec2(noise(rng), noise(rng));
      ASSERT_TRUE(undistort_pixel(*cams[k], noisy[k], xn[k]));
    }
    ASSERT_TRUE(triangulate_linear_nview(cams, xn, 3, Xl));
    double rms_start = 0.0, rms = 0.0;
    Vec3 Xs = Xl;
    ASSERT_TRUE(refine_gauss_newton(cams, noisy, 3, Xs, rms_start, 0));
    Vec3 Xg = Xl;
    ASSERT_TRUE(refine_gauss_newton(cams, noisy, 3, Xg, rms, 20));
    EXPECT_LE(rms, rms_start + 1e-12);
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      Vec2 p;
      Eigen::Matrix<double, 2, 3> J;
      ASSERT_TRUE(project(*cams[k], Xg, p, J));
      grad += J.transpose() * (p - noisy[k]);
    }
    EXPECT_LT(grad.norm(), 1e-6);
    // Each view's squared residual, from the same final evaluation as the RMS.
    double r2[3] = {-1.0, -1.0, -1.0};
    Vec3 Xr = Xl;
    double rms_r = 0.0;
    ASSERT_TRUE(refine_gauss_newton(cams, noisy, 3, Xr, rms_r, 20, 1e-9, r2));
    EXPECT_EQ(Xr, Xg);
    EXPECT_EQ(rms_r, rms);
    EXPECT_EQ(std::sqrt((r2[0] + r2[1] + r2[2]) / 3.0), rms);
    for (int k = 0; k < 3; ++k) {
      Vec2 p;
      ASSERT_TRUE(project(*cams[k], Xr, p));
      EXPECT_NEAR(r2[k], (p - noisy[k]).squaredNorm(), 1e-9 * (1.0 + r2[k]));
    }
  }
}

}  // namespace
}  // namespace mocap
