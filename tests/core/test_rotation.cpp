// Tests of the shared rotation conventions: quaternion sign, Euler XYZ round trips,
// gimbal lock, and the rotation check.
#include <gtest/gtest.h>

#include <random>

#include "core/rotation.h"

namespace mocap {
namespace {

TEST(Rotation, CanonicalQuatHasNonNegativeW) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const Quat q = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
    const Quat c = canonical_quat(q.toRotationMatrix());
    EXPECT_GE(c.w(), 0.0);
    EXPECT_NEAR(c.norm(), 1.0, 1e-12);
    EXPECT_LT((c.toRotationMatrix() - q.toRotationMatrix()).norm(), 1e-12);
  }
}

TEST(Rotation, EulerXyzRoundTrip) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> a(-3.1, 3.1), b(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 e(a(rng), b(rng), a(rng));
    const Vec3 back = rotation_to_euler_xyz(euler_xyz_to_rotation(e));
    EXPECT_LT((back - e).norm(), 1e-9) << e.transpose();
  }
}

TEST(Rotation, EulerXyzIsIntrinsicXThenYThenZ) {
  // R = Rx(a0) Ry(a1) Rz(a2): rotating the unit x axis by Rz(90deg) first gives y,
  // then Ry does not move y, then Rx(90deg) maps y to z.
  const double h = M_PI / 2.0;
  const Vec3 v = euler_xyz_to_rotation(Vec3(h, 0.0, h)) * Vec3::UnitX();
  EXPECT_LT((v - Vec3::UnitZ()).norm(), 1e-12);
}

TEST(Rotation, GimbalLockKeepsTheRotation) {
  const Mat3 R = euler_xyz_to_rotation(Vec3(0.3, M_PI / 2.0, 0.2));
  const Vec3 e = rotation_to_euler_xyz(R);
  EXPECT_NEAR(e[1], M_PI / 2.0, 1e-9);
  EXPECT_EQ(e[2], 0.0);
  EXPECT_LT((euler_xyz_to_rotation(e) - R).norm(), 1e-6);
}

TEST(Rotation, IsRotationRejectsReflectionsAndScaling) {
  EXPECT_TRUE(is_rotation(rot_z(0.7) * rot_x(-0.2)));
  Mat3 reflect = Mat3::Identity();
  reflect(2, 2) = -1.0;
  EXPECT_FALSE(is_rotation(reflect));
  EXPECT_FALSE(is_rotation(1.01 * Mat3::Identity()));
}

}  // namespace
}  // namespace mocap
