// Design: tests of the whole-marker shape model (track/marker_shape.h). The predicted
// silhouette covariance is checked against an independent numerical integration (every
// pixel of a fine grid undistorted with the camera model and tested against the ball's
// cone) for strong barrel and pincushion lenses, off-axis and near the border; check()
// is checked on shapes of whole and half-hidden discs and on flagged blobs.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "track/marker_shape.h"

namespace mocap {
namespace {

CameraModel lens(double k1, double k2, double f = 1200.0) {
  CameraModel c;
  c.name = "cam";
  c.width = 1280;
  c.height = 960;
  c.fx = f;
  c.fy = 0.98 * f;
  c.cx = 700.0;
  c.cy = 420.0;
  c.distortion = {k1, k2, 0.001, -0.0008, 0.0};
  return c;
}

// Moments of the silhouette of a ball by brute force: sub-pixel samples, each
// undistorted and tested against the cone; uniform fill.
Eigen::Matrix2d numeric_covariance(const CameraModel& cam, const Vec3& C, double radius,
                                   const Vec2& around_px, double half_px) {
  const double cos_a = std::sqrt(1.0 - radius * radius / C.squaredNorm());
  const Vec3 c = C.normalized();
  double n = 0.0;
  Vec2 s = Vec2::Zero();
  Eigen::Matrix2d ss = Eigen::Matrix2d::Zero();
  const double step = 0.1;
  for (double y = around_px.y() - half_px; y <= around_px.y() + half_px; y += step) {
    for (double x = around_px.x() - half_px; x <= around_px.x() + half_px; x += step) {
      Vec2 xn;
      if (!undistort_pixel(cam, Vec2(x, y), xn)) continue;
      const Vec3 r = Vec3(xn.x(), xn.y(), 1.0).normalized();
      if (r.dot(c) < cos_a) continue;
      const Vec2 p(x, y);
      n += 1.0;
      s += p;
      ss += p * p.transpose();
    }
  }
  const Vec2 m = s / n;
  return ss / n - m * m.transpose();
}

TEST(MarkerShape, PredictionMatchesNumericalSilhouette) {
  struct Case {
    double k1, k2;
    Vec3 C;
  };
  const Case cases[] = {
      {0.0, 0.0, Vec3(0.0, 0.0, 800.0)},          // on axis, pinhole
      {-0.38, 0.16, Vec3(300.0, -200.0, 700.0)},  // strong barrel, off axis
      {0.25, 0.05, Vec3(-330.0, 240.0, 900.0)},   // pincushion near the corner
      {-0.30, 0.09, Vec3(420.0, 10.0, 650.0)},    // near the border, 33 deg off axis
  };
  for (const Case& k : cases) {
    const CameraModel cam = lens(k.k1, k.k2);
    auto model = MarkerShapeModel::create(cam, 12.0, MarkerShapeConfig{});
    ASSERT_TRUE(model.ok());
    Eigen::Matrix2d S;
    Vec2 centre;
    ASSERT_TRUE(model->predict(k.C, S, centre));
    const double r_px = 2.0 * std::sqrt(S.trace());
    const Eigen::Matrix2d N = numeric_covariance(cam, k.C, 6.0, centre, 1.6 * r_px);
    EXPECT_LT((S - N).norm() / N.norm(), 0.01) << "k1 " << k.k1 << "\n" << S << "\n" << N;
  }
  auto model = MarkerShapeModel::create(lens(0, 0), 12.0, MarkerShapeConfig{});
  Eigen::Matrix2d S;
  Vec2 centre;
  EXPECT_FALSE(model->predict(Vec3(0, 0, -500.0), S, centre));  // behind the camera
  EXPECT_FALSE(model->predict(Vec3(0, 0, 3.0), S, centre));     // contains the pinhole
}

detect::Blob blob_from(const Eigen::Matrix2d& S, float area, float sum_dn) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  detect::Blob b;
  b.major_axis_px = static_cast<float>(2.0 * std::sqrt(es.eigenvalues()(1)));
  b.minor_axis_px = static_cast<float>(2.0 * std::sqrt(es.eigenvalues()(0)));
  b.orientation_rad =
      static_cast<float>(std::atan2(es.eigenvectors()(1, 1), es.eigenvectors()(0, 1)));
  b.area_px = area;
  b.sum_dn = sum_dn;
  return b;
}

TEST(MarkerShape, WholeAndHalfHiddenDiscs) {
  const CameraModel cam = lens(-0.38, 0.16);
  auto model = MarkerShapeModel::create(cam, 12.0, MarkerShapeConfig{});
  ASSERT_TRUE(model.ok());
  const Vec3 C(320.0, -180.0, 600.0);  // far off axis: an elongated silhouette
  Eigen::Matrix2d S;
  Vec2 centre;
  ASSERT_TRUE(model->predict(C, S, centre));
  const double area = M_PI * 4.0 * std::sqrt(S.determinant());  // filled ellipse
  const ImageNoise noise{12.0, 1.5, 24.0};
  const auto sum = static_cast<float>(area * 120.0);
  // Whole: any profile (k) and isotropic blur (b) keep it whole.
  for (double k : {1.0, 0.7, 0.45}) {
    for (double b : {0.0, 0.35, 1.2}) {
      const Eigen::Matrix2d M = k * S + b * Eigen::Matrix2d::Identity();
      const ShapeCheck r = model->check(blob_from(M, static_cast<float>(area), sum), C, noise);
      EXPECT_TRUE(r.whole) << "k " << k << " b " << b << " residual " << r.residual << " tol "
                           << r.tolerance;
    }
  }
  // Half hidden across the major axis and across the minor axis: the variance across
  // the cut drops to 0.28 of the disc's (1/4 - (4/(3 pi))^2 over 1/4).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  for (int axis = 0; axis < 2; ++axis) {
    const Vec2 u = es.eigenvectors().col(axis);
    const Eigen::Matrix2d M = S - 0.72 * es.eigenvalues()(axis) * u * u.transpose();
    const ShapeCheck r =
        model->check(blob_from(M, static_cast<float>(area / 2), sum / 2), C, noise);
    EXPECT_FALSE(r.whole) << "axis " << axis << " residual " << r.residual << " tol "
                          << r.tolerance;
  }
  // A rotated ellipse of the right size is not the predicted one either.
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(M_PI / 2).toRotationMatrix();
  EXPECT_FALSE(
      model->check(blob_from(R * S * R.transpose(), static_cast<float>(area), sum), C, noise)
          .whole);
  // Flags: never whole; disabled: only the flags decide.
  detect::Blob flagged = blob_from(S, static_cast<float>(area), sum);
  flagged.flags = detect::kBlobTouchesBorder;
  EXPECT_FALSE(model->check(flagged, C, noise).whole);
  MarkerShapeConfig off;
  off.enabled = false;
  auto loose = MarkerShapeModel::create(cam, 12.0, off);
  ASSERT_TRUE(loose.ok());
  EXPECT_TRUE(
      loose->check(blob_from(R * S * R.transpose(), static_cast<float>(area), sum), C, noise)
          .whole);
  EXPECT_FALSE(loose->check(flagged, C, noise).whole);
}

TEST(MarkerShape, SetupErrorsNameTheKey) {
  auto e = MarkerShapeModel::create(lens(0, 0), 0.0, MarkerShapeConfig{});
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("marker_diameter"), std::string::npos);
  MarkerShapeConfig bad;
  bad.false_partial_probability = 1.5;
  auto f = MarkerShapeModel::create(lens(0, 0), 12.0, bad);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("false_partial_probability"), std::string::npos);
}

}  // namespace
}  // namespace mocap
