// Tests of the pinhole + OpenCV 5-parameter distortion model (camera_model.h):
// hand-computed projections (arithmetic written out below), analytic Jacobians against
// central finite differences, and the undistortion round trip over the FULL image
// (dense grid including the corners and the outer pixel borders) for realistic and
// strong distortion.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "camera/camera_model.h"

namespace mocap {
namespace {

CameraModel make_camera(double f, std::array<double, 5> dist) {
  CameraModel c;
  c.name = "cam";
  c.width = 1032;
  c.height = 776;
  c.fx = f;
  c.fy = f;
  c.cx = 515.5;
  c.cy = 387.5;
  c.distortion = dist;
  return c;
}

TEST(CameraModel, HandComputedProjectionWithTangentialTerms) {
  // fx=1000, fy=900, cx=500, cy=400, [k1 k2 p1 p2 k3] = [-0.2 0.05 0.001 -0.002 0],
  // R = I, t = 0, X = (100, 50, 1000) mm.
  //   x' = 0.1, y' = 0.05, r2 = 0.01 + 0.0025 = 0.0125
  //   radial = 1 - 0.2*0.0125 + 0.05*0.0125^2 = 1 - 0.0025 + 0.0000078125 = 0.9975078125
  //   x'' = 0.1*0.9975078125 + 2*0.001*0.1*0.05 + (-0.002)*(0.0125 + 2*0.01)
  //       = 0.09975078125 + 0.00001 - 0.000065 = 0.09969578125
  //   y'' = 0.05*0.9975078125 + 0.001*(0.0125 + 2*0.0025) + 2*(-0.002)*0.1*0.05
  //       = 0.049875390625 + 0.0000175 - 0.00002 = 0.049872890625
  //   u = 1000*0.09969578125 + 500 = 599.69578125
  //   v = 900*0.049872890625 + 400 = 444.8856015625
  CameraModel c;
  c.fx = 1000.0;
  c.fy = 900.0;
  c.cx = 500.0;
  c.cy = 400.0;
  c.distortion = {-0.2, 0.05, 0.001, -0.002, 0.0};
  Vec2 px;
  ASSERT_TRUE(project(c, Vec3(100.0, 50.0, 1000.0), px));
  EXPECT_NEAR(px.x(), 599.69578125, 1e-9);
  EXPECT_NEAR(px.y(), 444.8856015625, 1e-9);
}

TEST(CameraModel, HandComputedProjectionWithExtrinsicsAndK3) {
  // fx=fy=800, cx=320, cy=240, [k1 k2 p1 p2 k3] = [0.1 -0.05 0 0 0.02],
  // R = [[0,-1,0],[1,0,0],[0,0,1]], t = (10, -20, 500), X_world = (30, 40, 500):
  //   X_cam = (-40 + 10, 30 - 20, 500 + 500) = (-30, 10, 1000)
  //   x' = -0.03, y' = 0.01, r2 = 0.0009 + 0.0001 = 0.001
  //   radial = 1 + 0.1*0.001 - 0.05*1e-6 + 0.02*1e-9 = 1.00009995002
  //   x'' = -0.0300029985006, y'' = 0.0100009995002
  //   u = 800*(-0.0300029985006) + 320 = 295.99760119952
  //   v = 800*0.0100009995002 + 240 = 248.00079960016
  CameraModel c;
  c.fx = 800.0;
  c.fy = 800.0;
  c.cx = 320.0;
  c.cy = 240.0;
  c.distortion = {0.1, -0.05, 0.0, 0.0, 0.02};
  c.R_cam_world << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  c.t_cam_world = Vec3(10.0, -20.0, 500.0);
  Vec2 px;
  ASSERT_TRUE(project(c, Vec3(30.0, 40.0, 500.0), px));
  EXPECT_NEAR(px.x(), 295.99760119952, 1e-9);
  EXPECT_NEAR(px.y(), 248.00079960016, 1e-9);
}

TEST(CameraModel, HandComputedPureTangential) {
  // Only p1 = 0.01, p2 = 0.02; f = 1000, c = (0, 0); x' = 0.2, y' = -0.1:
  //   r2 = 0.05, radial = 1
  //   x'' = 0.2 + 2*0.01*0.2*(-0.1) + 0.02*(0.05 + 2*0.04) = 0.2 - 0.0004 + 0.0026 = 0.2022
  //   y'' = -0.1 + 0.01*(0.05 + 2*0.01) + 2*0.02*0.2*(-0.1) = -0.1 + 0.0007 - 0.0008
  //       = -0.1001
  CameraModel c;
  c.fx = c.fy = 1000.0;
  c.distortion = {0.0, 0.0, 0.01, 0.02, 0.0};
  const Vec2 px = normalized_to_pixel(c, Vec2(0.2, -0.1));
  EXPECT_NEAR(px.x(), 202.2, 1e-9);
  EXPECT_NEAR(px.y(), -100.1, 1e-9);
}

TEST(CameraModel, PointBehindCameraIsRejected) {
  CameraModel c = make_camera(1290.0, {-0.1, 0.0, 0.0, 0.0, 0.0});
  Vec2 px(-7.0, -7.0);
  EXPECT_FALSE(project(c, Vec3(10.0, 10.0, -500.0), px));
  EXPECT_FALSE(project(c, Vec3(10.0, 10.0, 0.0), px));
  EXPECT_EQ(px, Vec2(-7.0, -7.0));
  Eigen::Matrix<double, 2, 3> J;
  EXPECT_FALSE(project(c, Vec3(0.0, 0.0, -1.0), px, J));
}

Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

// to_camera() is a written-out R * X + t: bit for bit Eigen's fixed-size product (the
// tracker's outputs must not change with it), over rotations, translations and points of
// every scale.
TEST(CameraModel, ToCameraIsBitIdenticalToEigensProduct) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-6, 6);
  CameraModel c = make_camera(1000.0, {0.0, 0.0, 0.0, 0.0, 0.0});
  for (int trial = 0; trial < 200000; ++trial) {
    c.R_cam_world = random_rotation(rng);
    const double st = std::ldexp(1.0, 2 * e(rng)), sx = std::ldexp(1.0, 2 * e(rng));
    c.t_cam_world = Vec3(st * u(rng), st * u(rng), st * u(rng));
    const Vec3 X(sx * u(rng), sx * u(rng), sx * u(rng));
    const Vec3 expected = c.R_cam_world * X + c.t_cam_world;
    const Vec3 got = to_camera(c, X);
    ASSERT_EQ(got.x(), expected.x()) << "trial " << trial;
    ASSERT_EQ(got.y(), expected.y()) << "trial " << trial;
    ASSERT_EQ(got.z(), expected.z()) << "trial " << trial;
  }
}

TEST(CameraModel, ProjectionJacobianMatchesCentralDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CameraModel c = make_camera(1290.0, {-0.25, 0.12, 0.0012, -0.0009, -0.03});
  c.fy = 1280.0;
  for (int trial = 0; trial < 200; ++trial) {
    c.R_cam_world = random_rotation(rng);
    c.t_cam_world = Vec3(100 * u(rng), 100 * u(rng), 100 * u(rng));
    // A point in front, within the field of view.
    const Vec3 X_cam(400 * u(rng), 300 * u(rng), 1000 + 500 * u(rng));
    const Vec3 X = c.R_cam_world.transpose() * (X_cam - c.t_cam_world);
    Vec2 px, px_plain;
    Eigen::Matrix<double, 2, 3> J;
    ASSERT_TRUE(project(c, X, px, J));
    ASSERT_TRUE(project(c, X, px_plain));
    EXPECT_LT((px - px_plain).norm(), 1e-9);  // x * (1/z) vs x / z rounding
    const double h = 1e-3;                    // mm
    for (int k = 0; k < 3; ++k) {
      Vec3 Xp = X, Xm = X;
      Xp[k] += h;
      Xm[k] -= h;
      Vec2 pp, pm;
      ASSERT_TRUE(project(c, Xp, pp));
      ASSERT_TRUE(project(c, Xm, pm));
      const Vec2 fd = (pp - pm) / (2 * h);
      EXPECT_NEAR(J(0, k), fd.x(), 1e-6 * (1.0 + J.norm())) << "trial " << trial;
      EXPECT_NEAR(J(1, k), fd.y(), 1e-6 * (1.0 + J.norm())) << "trial " << trial;
    }
  }
}

TEST(CameraModel, DistortionJacobianMatchesCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  const CameraModel c = make_camera(1000.0, {-0.3, 0.1, 0.002, -0.003, 0.05});
  for (int trial = 0; trial < 200; ++trial) {
    const Vec2 xn(u(rng), u(rng));
    const Eigen::Matrix2d J = distort_jacobian(c, xn);
    const double h = 1e-6;
    for (int k = 0; k < 2; ++k) {
      Vec2 p = xn, m = xn;
      p[k] += h;
      m[k] -= h;
      const Vec2 fd = (distort_normalized(c, p) - distort_normalized(c, m)) / (2 * h);
      EXPECT_NEAR(J(0, k), fd.x(), 1e-8);
      EXPECT_NEAR(J(1, k), fd.y(), 1e-8);
    }
  }
}

// Undistorts every pixel of a dense grid covering the whole image (step 3 px, plus
// the last column/row, the outer pixel borders at -0.5 and size-0.5 and the exact
// corners) and re-distorts it; returns the largest round-trip error in pixels.
double max_round_trip_error_px(const CameraModel& c, int* failures) {
  double worst = 0.0;
  *failures = 0;
  auto check = [&](double x, double y) {
    Vec2 xn;
    if (!undistort_pixel(c, Vec2(x, y), xn)) {
      ++*failures;
      return;
    }
    worst = std::max(worst, (normalized_to_pixel(c, xn) - Vec2(x, y)).norm());
  };
  for (double y = -0.5;; y += 3.0) {
    const double yy = std::min(y, c.height - 0.5);
    for (double x = -0.5;; x += 3.0) {
      const double xx = std::min(x, c.width - 0.5);
      check(xx, yy);
      if (xx >= c.width - 0.5) break;
    }
    if (yy >= c.height - 0.5) break;
  }
  check(0.0, 0.0);
  check(c.width - 1.0, 0.0);
  check(0.0, c.height - 1.0);
  check(c.width - 1.0, c.height - 1.0);
  return worst;
}

TEST(CameraModel, UndistortRoundTripFullImageRealistic) {
  int failures = 0;
  const CameraModel c = make_camera(1290.3, {-0.12, 0.09, 0.0005, -0.0003, -0.01});
  EXPECT_LT(max_round_trip_error_px(c, &failures), 1e-6);
  EXPECT_EQ(failures, 0);
}

TEST(CameraModel, UndistortRoundTripFullImageStrongBarrel) {
  int failures = 0;
  const CameraModel c = make_camera(1290.3, {-0.3, 0.1, 0.001, -0.001, 0.0});
  EXPECT_LT(max_round_trip_error_px(c, &failures), 1e-6);
  EXPECT_EQ(failures, 0);
}

TEST(CameraModel, UndistortRoundTripFullImageStrongBarrelWideAngle) {
  // f = 700 px: the corners reach r'' = 0.92, where k1 = -0.3, k2 = 0.1 bend strongly.
  int failures = 0;
  const CameraModel c = make_camera(700.0, {-0.3, 0.1, 0.0, 0.0, 0.0});
  EXPECT_LT(max_round_trip_error_px(c, &failures), 1e-6);
  EXPECT_EQ(failures, 0);
}

TEST(CameraModel, UndistortRoundTripFullImagePincushion) {
  int failures = 0;
  CameraModel c = make_camera(1000.0, {0.15, -0.02, -0.001, 0.002, 0.0});
  c.fy = 1010.0;
  EXPECT_LT(max_round_trip_error_px(c, &failures), 1e-6);
  EXPECT_EQ(failures, 0);
}

TEST(CameraModel, UndistortInvertsKnownDistortion) {
  const CameraModel c = make_camera(1290.3, {-0.3, 0.1, 0.001, -0.001, 0.0});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.45, 0.45);
  for (int i = 0; i < 500; ++i) {
    const Vec2 xn(u(rng), 0.75 * u(rng));
    Vec2 back;
    ASSERT_TRUE(undistort_pixel(c, normalized_to_pixel(c, xn), back));
    EXPECT_NEAR((back - xn).norm(), 0.0, 1e-12);
  }
}

TEST(CameraModel, PixelRayPassesThroughThePoint) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CameraModel c = make_camera(1290.3, {-0.2, 0.08, 0.0008, 0.0004, 0.0});
  c.R_cam_world = random_rotation(rng);
  c.t_cam_world = Vec3(50.0, -30.0, 900.0);
  for (int i = 0; i < 100; ++i) {
    const Vec3 X_cam(350 * u(rng), 250 * u(rng), 1000 + 300 * u(rng));
    const Vec3 X = c.R_cam_world.transpose() * (X_cam - c.t_cam_world);
    Vec2 px;
    ASSERT_TRUE(project(c, X, px));
    Vec3 dir;
    ASSERT_TRUE(pixel_ray_world(c, px, dir));
    EXPECT_NEAR(dir.norm(), 1.0, 1e-12);
    const Vec3 to_point = (X - c.center_world()).normalized();
    EXPECT_NEAR((dir - to_point).norm(), 0.0, 1e-10);
  }
}

// The exact silhouette of a ball (radius R at X_cam) in the image: the circle where the
// tangent cone touches it, projected through the full model. Its centre as an edge fit
// finds it: the first Fourier harmonic of the contour's radius over the image angle
// about the centre (recentred until it stays); its half width across the radial
// direction: the mean radius over the two across directions' neighbourhoods.
struct Silhouette {
  Vec2 centre_px;
  double half_width_px;
};
Silhouette ball_silhouette(const CameraModel& c, const Vec3& X, double R) {
  const double D = X.norm();
  const Vec3 w = X / D;
  const Vec3 a = w.cross(Vec3::UnitZ()).norm() > 1e-9 ? Vec3(w.cross(Vec3::UnitZ()).normalized())
                                                      : Vec3::UnitX();
  const Vec3 b = w.cross(a);
  const double rho = R * std::sqrt(D * D - R * R) / D;  // the tangency circle
  const Vec3 ring = X - w * (R * R / D);
  std::vector<Vec2> contour;
  for (int k = 0; k < 1440; ++k) {
    const double phi = 2.0 * M_PI * k / 1440.0;
    Vec2 px;
    EXPECT_TRUE(project(c, ring + rho * (std::cos(phi) * a + std::sin(phi) * b), px));
    contour.push_back(px);
  }
  Vec2 centre;
  EXPECT_TRUE(project(c, X, centre));
  Vec2 radial = centre - Vec2(c.cx, c.cy);
  radial = radial.norm() > 1e-9 ? Vec2(radial.normalized()) : Vec2(1.0, 0.0);
  const Vec2 across(-radial.y(), radial.x());
  double half_width = 0.0;
  for (int iter = 0; iter < 6; ++iter) {
    Vec2 harmonic = Vec2::Zero();
    double w_across = 0.0, r_across = 0.0;
    for (std::size_t k = 0; k < contour.size(); ++k) {
      const Vec2 p = contour[k] - centre, q = contour[(k + 1) % contour.size()] - centre;
      // Trapezoid in the image angle: r e(psi) dpsi over the segment.
      double dpsi = std::atan2(p.x() * q.y() - p.y() * q.x(), p.dot(q));
      const Vec2 mid = 0.5 * (p + q);
      harmonic += mid * std::fabs(dpsi);
      const double cos_across = std::fabs(mid.normalized().dot(across));
      if (cos_across > std::cos(2.0 * M_PI / 180.0)) {
        w_across += std::fabs(dpsi);
        r_across += mid.norm() * std::fabs(dpsi);
      }
    }
    centre += harmonic / M_PI;
    half_width = r_across / w_across;
  }
  return {centre, half_width};
}

TEST(CameraModel, BallCentreFromItsSilhouette) {
  // A 12 mm ball: the silhouette's centre (as an edge fit finds it) lies outwards of the
  // projection by up to a few thousandths of a pixel, growing with the angle off axis;
  // barrel distortion pulls it back in. ball_centre_pixel() recovers the projection to
  // within 2 % of that offset, for a normal lens 2.5 m away and a wide one 1 m away.
  struct Case {
    double f, distance_mm;
    std::array<double, 5> dist;
  };
  for (const Case& k :
       {Case{1290.3, 2500.0, {}}, Case{1290.3, 2500.0, {-0.25, 0.1, 5e-4, -3e-4, 0.0}},
        Case{700.0, 1000.0, {-0.3, 0.1, 0.0, 0.0, 0.0}},
        Case{1000.0, 1500.0, {0.15, -0.02, -0.001, 0.002, 0.0}}}) {
    const CameraModel c = make_camera(k.f, k.dist);
    double largest = 0.0;
    for (double deg : {0.0, 5.0, 12.0, 18.0, 25.0}) {
      const double t = std::tan(deg * M_PI / 180.0);
      const Vec3 X = Vec3(t * 0.8, t * 0.6, 1.0).normalized() * k.distance_mm;
      Vec2 p;
      ASSERT_TRUE(project(c, X, p));
      const Silhouette s = ball_silhouette(c, X, 6.0);
      Vec2 got;
      ASSERT_TRUE(ball_centre_pixel(c, s.centre_px, s.half_width_px, got));
      const double before = (s.centre_px - p).norm(), after = (got - p).norm();
      largest = std::max(largest, before);
      // 2 % of the offset, or 2e-6 px where the lens all but cancels it.
      EXPECT_LE(after, 0.02 * before + 2e-6) << "f " << k.f << " deg " << deg;
    }
    EXPECT_GT(largest, 2e-4) << "f " << k.f;
  }
  Vec2 out;
  const CameraModel c = make_camera(1290.3, {});
  EXPECT_FALSE(ball_centre_pixel(c, Vec2(100.0, 100.0), 0.0, out));
  EXPECT_EQ(out, Vec2(100.0, 100.0));
}

}  // namespace
}  // namespace mocap
