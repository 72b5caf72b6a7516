// Design: tests of the consistency test (identify/consistency.h): the chi-square
// quantile, a biased marker dropped by leave-one-out (and its point freed), a solution
// that noise cannot explain rejected, a stray completing a triangle rejected, and the
// false-rejection rate of clean fits at the configured noise; the weighted fit of partial
// markers in coverage mode and the weighted rigid fit itself.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "identify/consistency.h"
#include "identify/identifier.h"
#include "identify/rigid_fit.h"
#include "tests/identify/identify_test_util.h"

namespace mocap {
namespace {

TEST(Consistency, ChiSquareQuantileMatchesTables) {
  // Exact values: chi2(3, 0.9999) = 21.108, chi2(9, 0.9999) = 33.720, chi2(9, 0.99) = 21.666.
  EXPECT_NEAR(chi2_quantile(3, 0.9999), 21.108, 0.04 * 21.108);
  EXPECT_NEAR(chi2_quantile(9, 0.9999), 33.720, 0.02 * 33.720);
  EXPECT_NEAR(chi2_quantile(9, 0.99), 21.666, 0.01 * 21.666);
  EXPECT_NEAR(chi2_quantile(30, 0.999), 59.703, 0.01 * 59.703);
}

struct OneBody {
  TargetSet set;
  Iso3 T_world_body = Iso3::Identity();
  std::vector<MeasuredPoint> pts;  // marker c at index c
};

OneBody make_body(std::mt19937_64& rng, int k, double noise_mm) {
  OneBody b;
  b.set.bodies.push_back(test::random_target(rng, k, "limb"));
  b.T_world_body.linear() = test::random_rotation(rng);
  b.T_world_body.translation() = Vec3(100.0, -50.0, 1500.0);
  std::normal_distribution<double> g(0.0, noise_mm);
  for (int c = 0; c < k; ++c) {
    MeasuredPoint p;
    p.X_world = b.T_world_body * b.set.bodies[0].markers_body[static_cast<std::size_t>(c)] +
                Vec3(g(rng), g(rng), g(rng));
    p.blob_index = {static_cast<std::int16_t>(c), static_cast<std::int16_t>(c)};
    b.pts.push_back(p);
  }
  return b;
}

TEST(Consistency, BiasedMarkerIsDroppedAndPoseStaysAccurate) {
  std::mt19937_64 rng(5);
  IdentifyConfig cfg;
  cfg.temporal = false;
  cfg.point_sigma_mm = 0.1;  // the noise below is 0.02 mm
  int dropped_right = 0;
  for (int trial = 0; trial < 50; ++trial) {
    OneBody b = make_body(rng, 5, 0.02);
    // A partly occluded marker (not flagged): its centroid biased by 1.2 mm, well inside
    // t = 5 mm; the paper's search alone keeps it (score with all 5 markers is lower).
    b.pts[2].X_world += Vec3(0.7, -0.6, 0.7);
    IdentifyConfig paper_cfg = cfg;
    paper_cfg.point_sigma_mm = 0.0;
    auto paper = Identifier::create(b.set, paper_cfg);
    ASSERT_TRUE(paper.ok());
    BodyPoses paper_out;
    paper->identify(b.pts.data(), static_cast<int>(b.pts.size()), 0, paper_out);
    EXPECT_EQ(paper_out.bodies[0].markers, 5);
    auto id = Identifier::create(b.set, cfg);
    ASSERT_TRUE(id.ok());
    BodyPoses out;
    id->identify(b.pts.data(), static_cast<int>(b.pts.size()), 0, out);
    const BodyPose& p = out.bodies[0];
    ASSERT_TRUE(p.found);
    EXPECT_EQ(p.markers, 4);
    EXPECT_EQ(p.point_index_of_marker[2], -1);
    dropped_right += p.point_index_of_marker[2] == -1;
    EXPECT_LT((p.T_world_body.translation() - b.T_world_body.translation()).norm(), 0.1);
    EXPECT_EQ(id->counters().outlier_markers, 1U);
  }
  EXPECT_EQ(dropped_right, 50);
}

TEST(Consistency, ThreeMarkersWithABiasedOneAreRejected) {
  std::mt19937_64 rng(6);
  IdentifyConfig cfg;
  cfg.temporal = false;
  OneBody b = make_body(rng, 4, 0.02);
  b.pts.pop_back();  // 3 visible markers
  // Marker 1 pushed 3 mm away from the triangle's centroid: the side lengths change by
  // up to 3 mm, inside t, and the 3-point fit cannot absorb it.
  const Vec3 centroid = (b.pts[0].X_world + b.pts[1].X_world + b.pts[2].X_world) / 3.0;
  b.pts[1].X_world += 3.0 * (b.pts[1].X_world - centroid).normalized();
  auto id = Identifier::create(b.set, cfg);
  ASSERT_TRUE(id.ok());
  BodyPoses out;
  id->identify(b.pts.data(), 3, 0, out);
  EXPECT_FALSE(out.bodies[0].found);
  EXPECT_EQ(id->counters().consistency_rejects, 1U);
  // The same frame with the test disabled (the paper's gate t only) accepts the biased pose.
  cfg.point_sigma_mm = 0.0;
  auto paper = Identifier::create(b.set, cfg);
  ASSERT_TRUE(paper.ok());
  paper->identify(b.pts.data(), 3, 0, out);
  EXPECT_TRUE(out.bodies[0].found);
}

TEST(Consistency, PartialMarkersStayMatchedButOutOfTheFit) {
  std::mt19937_64 rng(8);
  IdentifyConfig cfg;
  cfg.temporal = false;
  IdentifyConfig all_cfg = cfg;  // every matched marker in the fit
  all_cfg.exclude_partial_markers = false;
  all_cfg.partial_sigma_mm = 0.0;  // and weighted like whole ones
  double sum_sq_whole = 0.0, sum_sq_all = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    OneBody b = make_body(rng, 5, 0.02);
    // Two partly occluded markers, biased by 0.6 mm: within every gate, but they would
    // pull the pose by a few tenths of a millimetre.
    for (int c : {1, 3}) {
      b.pts[static_cast<std::size_t>(c)].X_world += Vec3(0.6, 0.0, 0.0);
      b.pts[static_cast<std::size_t>(c)].partial = true;
    }
    auto id = Identifier::create(b.set, cfg);
    ASSERT_TRUE(id.ok());
    BodyPoses out;
    id->identify(b.pts.data(), 5, 0, out);
    const BodyPose& p = out.bodies[0];
    ASSERT_TRUE(p.found);
    EXPECT_EQ(p.markers, 5);  // still identified
    EXPECT_EQ(p.point_index_of_marker[1], 1);
    EXPECT_EQ(p.point_index_of_marker[3], 3);
    sum_sq_whole += (p.T_world_body.translation() - b.T_world_body.translation()).squaredNorm();
    EXPECT_EQ(id->counters().partial_excluded, 2U);
    auto all = Identifier::create(b.set, all_cfg);
    ASSERT_TRUE(all.ok());
    all->identify(b.pts.data(), 5, 0, out);
    ASSERT_TRUE(out.bodies[0].found);
    sum_sq_all +=
        (out.bodies[0].T_world_body.translation() - b.T_world_body.translation()).squaredNorm();
    // With only 2 whole markers: not reported by default (min_whole_markers = 3) ...
    b.pts[0].partial = true;
    id->reset();  // an independent frame (no prior, no speed limit)
    id->identify(b.pts.data(), 5, 1, out);
    EXPECT_FALSE(out.bodies[0].found);
    EXPECT_EQ(id->counters().partial_rejects, 1U);
    // ... and with min_whole_markers = 0, all 5 are fitted.
    IdentifyConfig coverage_cfg = cfg;
    coverage_cfg.min_whole_markers = 0;
    auto coverage = Identifier::create(b.set, coverage_cfg);
    ASSERT_TRUE(coverage.ok());
    coverage->identify(b.pts.data(), 5, 1, out);
    ASSERT_TRUE(out.bodies[0].found);
    EXPECT_EQ(out.bodies[0].markers, 5);
    EXPECT_EQ(coverage->counters().partial_excluded, 0U);
  }
  // The biased markers pull the all-marker pose; the whole-marker pose is far better.
  EXPECT_LT(std::sqrt(sum_sq_whole / 20), 0.4 * std::sqrt(sum_sq_all / 20));
}

TEST(Consistency, CleanFitsAreRarelyRejected) {
  // At the configured noise (sigma = point_sigma_mm per coordinate) the false-rejection
  // rate is about 1 - consistency_confidence; over 2000 fits of 3..6 markers, at most 0.5%.
  std::mt19937_64 rng(7);
  IdentifyConfig cfg;
  cfg.temporal = false;
  cfg.point_sigma_mm = 0.2;
  int rejected = 0, dropped = 0;
  const int trials = test::scaled_trials(2000);
  for (int trial = 0; trial < trials; ++trial) {
    const int k = 3 + trial % 4;
    OneBody b = make_body(rng, k, cfg.point_sigma_mm);
    auto id = Identifier::create(b.set, cfg);
    ASSERT_TRUE(id.ok());
    BodyPoses out;
    id->identify(b.pts.data(), k, 0, out);
    rejected += !out.bodies[0].found;
    dropped += static_cast<int>(id->counters().outlier_markers);
  }
  EXPECT_LE(rejected * 200, trials) << rejected << " of " << trials;
  EXPECT_LE(dropped * 200, trials) << dropped << " markers dropped";
}

TEST(Consistency, WeightedRigidFitMatchesUmeyamaAndFollowsTheWeights) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int m = 3 + trial % 6;
    Iso3 T = Iso3::Identity();
    T.linear() = test::random_rotation(rng);
    T.translation() = Vec3(g(rng), g(rng), g(rng)) * 500.0;
    FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
    FitWeights w{};
    for (int i = 0; i < m; ++i) {
      src.col(i) = Vec3(g(rng), g(rng), g(rng)) * 60.0;
      dst.col(i) = T * Vec3(src.col(i)) + Vec3(g(rng), g(rng), g(rng)) * 0.1;
      w[static_cast<std::size_t>(i)] = 1.0;
    }
    const RigidFit ref = fit_rigid(src, dst, m);
    const RigidFit fit = fit_rigid_weighted(src, dst, w, m);
    EXPECT_TRUE(fit.T_dst_src.isApprox(ref.T_dst_src, 1e-9));
    EXPECT_NEAR(fit.sum_sq_mm2, ref.sum_sq_mm2, 1e-9);
    EXPECT_NEAR(fit.T_dst_src.linear().determinant(), 1.0, 1e-12);
    // Exact data on the first 3 columns with a huge weight, the others shifted by 5 mm:
    // the fit follows the heavy columns.
    for (int i = 0; i < m; ++i) {
      const bool heavy = i < 3;
      dst.col(i) = T * Vec3(src.col(i)) + (heavy ? Vec3::Zero() : Vec3(5.0, 0.0, 0.0));
      w[static_cast<std::size_t>(i)] = heavy ? 1e6 : 1.0;
    }
    const RigidFit heavy = fit_rigid_weighted(src, dst, w, m);
    EXPECT_LT((heavy.T_dst_src.translation() - T.translation()).norm(), 0.01);
  }
}

TEST(Consistency, CoverageModeWeighsPartialMarkersAndNeedsARedundantFit) {
  std::mt19937_64 rng(22);
  std::normal_distribution<double> g(0.0, 1.0);
  IdentifyConfig cfg;
  cfg.temporal = false;
  cfg.min_whole_markers = 0;
  IdentifyConfig equal_cfg = cfg;  // partial markers weighted like whole ones
  equal_cfg.partial_sigma_mm = 0.0;
  int found_weighted = 0, kept_equal = 0;
  for (int trial = 0; trial < 20; ++trial) {
    OneBody b = make_body(rng, 5, 0.02);
    // 2 whole markers (0, 2), 3 partial ones biased by 1 mm in random directions: no pose
    // from whole markers, and an equal-weight fit cannot explain the biases.
    for (int c : {1, 3, 4}) {
      b.pts[static_cast<std::size_t>(c)].X_world += Vec3(g(rng), g(rng), g(rng)).normalized();
      b.pts[static_cast<std::size_t>(c)].partial = true;
    }
    auto id = Identifier::create(b.set, cfg);
    ASSERT_TRUE(id.ok());
    BodyPoses out;
    id->identify(b.pts.data(), 5, 0, out);
    if (out.bodies[0].found && out.bodies[0].markers == 5) ++found_weighted;
    auto equal = Identifier::create(b.set, equal_cfg);
    ASSERT_TRUE(equal.ok());
    equal->identify(b.pts.data(), 5, 0, out);
    if (out.bodies[0].found && out.bodies[0].markers == 5) ++kept_equal;
    // 2 whole + 1 partial = 3 markers: every bias of the partial one would pass into the
    // pose unseen, so the pose is not reported even in coverage mode.
    OneBody three = b;
    three.pts.resize(3);
    id->identify(three.pts.data(), 3, 1, out);
    EXPECT_FALSE(out.bodies[0].found);
  }
  EXPECT_EQ(found_weighted, 20);
  EXPECT_LT(kept_equal, 5);
}

TEST(Consistency, ConfigurationIsValidated) {
  IdentifyConfig cfg;
  cfg.point_sigma_mm = -1.0;
  EXPECT_NE(validate_config(cfg).error().message.find("point_sigma_mm"), std::string::npos);
  cfg = IdentifyConfig{};
  cfg.partial_sigma_mm = 0.1;  // below point_sigma_mm
  EXPECT_NE(validate_config(cfg).error().message.find("partial_sigma_mm"), std::string::npos);
  cfg = IdentifyConfig{};
  cfg.consistency_confidence = 0.5;
  EXPECT_NE(validate_config(cfg).error().message.find("consistency_confidence"), std::string::npos);
}

}  // namespace
}  // namespace mocap
