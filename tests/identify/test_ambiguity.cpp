// Design: tests of the load-time ambiguity detection: symmetric targets, mirror-image
// targets, shared subsets; unambiguous targets give no warning; the reject policy.
#include <gtest/gtest.h>

#include <random>

#include "identify/identifier.h"
#include "tests/identify/identify_test_util.h"

namespace mocap {
namespace {

TEST(Ambiguity, SymmetricTargetIsReported) {
  TargetSet set;
  set.bodies.push_back(
      {"square", {Vec3(0, 0, 0), Vec3(80, 0, 0), Vec3(80, 80, 0), Vec3(0, 80, 0)}});
  auto id = Identifier::create(set, IdentifyConfig{});
  ASSERT_TRUE(id.ok());
  ASSERT_EQ(id->ambiguities().size(), 1u);
  const auto& f = id->ambiguities()[0];
  EXPECT_EQ(f.body_a, 0);
  EXPECT_EQ(f.body_b, 0);
  EXPECT_EQ(f.markers, 4);
  EXPECT_LT(f.rms_mm, 1e-9);
  EXPECT_NE(id->warnings()[0].find("'square'"), std::string::npos);
  EXPECT_NE(id->warnings()[0].find("symmetric"), std::string::npos);
  IdentifyConfig reject;
  reject.ambiguity_policy = AmbiguityPolicy::kReject;
  auto e = Identifier::create(set, reject);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("'square'"), std::string::npos);
}

TEST(Ambiguity, DistinctTargetsAreNotReported) {
  TargetSet set;
  set.bodies.push_back({"a", {Vec3(0, 0, 0), Vec3(100, 0, 0), Vec3(0, 45, 0), Vec3(0, 0, 70)}});
  set.bodies.push_back({"b", {Vec3(0, 0, 0), Vec3(200, 0, 0), Vec3(0, 160, 0), Vec3(0, 0, 250)}});
  auto id = Identifier::create(set, IdentifyConfig{});
  ASSERT_TRUE(id.ok());
  EXPECT_TRUE(id->warnings().empty()) << id->warnings()[0];
}

// Mirror images (left/right limbs): every triangle is congruent, so 3 markers confuse.
TEST(Ambiguity, MirrorImageTargetIsReported) {
  std::mt19937_64 rng(9);
  TargetSet set;
  set.bodies.push_back(test::random_target(rng, 5, "left", 75.0, 6.0));
  MarkerTarget mirror = set.bodies[0];
  mirror.name = "right";
  for (Vec3& p : mirror.markers_body) p.x() = -p.x();
  set.bodies.push_back(mirror);
  auto id = Identifier::create(set, IdentifyConfig{});
  ASSERT_TRUE(id.ok());
  bool pair_reported = false;
  for (const auto& f : id->ambiguities()) {
    if (f.body_a == 0 && f.body_b == 1) {
      pair_reported = true;
      EXPECT_GE(f.markers, 3);
      EXPECT_LT(f.markers, 5);  // a non-planar target is not congruent to its mirror
    }
  }
  EXPECT_TRUE(pair_reported);
}

TEST(Ambiguity, SubsetOfAnotherTargetIsReported) {
  std::mt19937_64 rng(10);
  TargetSet set;
  set.bodies.push_back(test::random_target(rng, 5, "big", 75.0, 6.0));
  MarkerTarget sub{"small", {}};
  const Iso3 T = Eigen::Translation3d(5, -3, 7) * Eigen::AngleAxisd(0.7, Vec3::UnitY());
  for (int c = 0; c < 4; ++c)
    sub.markers_body.push_back(T * set.bodies[0].markers_body[static_cast<std::size_t>(c)]);
  set.bodies.push_back(sub);
  auto id = Identifier::create(set, IdentifyConfig{});
  ASSERT_TRUE(id.ok());
  ASSERT_EQ(id->ambiguities().size(), 1u);  // distinct distances: neither is self-similar
  EXPECT_EQ(id->ambiguities()[0].body_a, 0);
  EXPECT_EQ(id->ambiguities()[0].body_b, 1);
  EXPECT_EQ(id->ambiguities()[0].markers, 4);
  EXPECT_NE(id->warnings()[0].find("'big' and 'small'"), std::string::npos);
}

}  // namespace
}  // namespace mocap
