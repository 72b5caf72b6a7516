// Design: tests of the single-target Eq. 1 search (TargetSearch) against the exhaustive
// reference, mutually exclusive candidates, and the setup-time validation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "identify/exhaustive_search.h"
#include "identify/rigid_fit.h"
#include "identify/target_search.h"
#include "tests/identify/identify_test_util.h"

namespace mocap {
namespace {

using test::make_scene;
using test::random_target;
using test::SceneOptions;

TargetModel model_of(const MarkerTarget& t, const IdentifyConfig& cfg = {}) {
  auto m = make_target_model(t, cfg, "bodies[0]");
  EXPECT_TRUE(m.ok());
  return *m;
}

TEST(TargetSearch, FindsNoiseFreeTargetExactly) {
  std::mt19937_64 rng(1);
  TargetSet set;
  set.bodies.push_back(random_target(rng, 5, "a"));
  const TargetModel model = model_of(set.bodies[0]);
  IdentifyConfig cfg;
  FramePoints frame(cfg.max_points);
  TargetSearch search(cfg);
  for (int trial = 0; trial < 50; ++trial) {
    const auto scene = make_scene(rng, set, SceneOptions{0.0, 5, false, 3, 300.0});
    frame.load(scene.pts.data(), static_cast<int>(scene.pts.size()), model.max_pair_mm + cfg.t_mm);
    SearchResult r;
    SearchStats st;
    ASSERT_TRUE(search.run(model, frame, r, st));
    EXPECT_EQ(r.m, 5);
    EXPECT_LT(r.rms_mm, 1e-6);
    EXPECT_LE(st.seeds, cfg.best_pairs);
    EXPECT_FALSE(st.node_limit_hit);
    for (int c = 0; c < 5; ++c)
      EXPECT_EQ(r.point_of_marker[static_cast<std::size_t>(c)],
                scene.truth[0][static_cast<std::size_t>(c)]);
    EXPECT_TRUE(r.T_world_body.isApprox(scene.T_world_body[0], 1e-9));
  }
}

// The heuristic search agrees with the exhaustive enumeration on small cases: same
// assignment and score, including occlusion down to 3 markers and strays.
TEST(TargetSearch, AgreesWithExhaustiveSearch) {
  std::mt19937_64 rng(7);
  IdentifyConfig cfg;
  FramePoints frame(cfg.max_points);
  TargetSearch search(cfg);
  int found = 0, unique = 0;
  const int trials = test::scaled_trials(400);
  for (int trial = 0; trial < trials; ++trial) {
    const int k = 4 + trial % 2;
    TargetSet set;
    set.bodies.push_back(random_target(rng, k, "a"));
    const TargetModel model = model_of(set.bodies[0]);
    SceneOptions opt;
    opt.noise_mm = 0.3;
    opt.occlude = true;
    opt.strays = 8 - k;  // up to 8 points in all
    const auto scene = make_scene(rng, set, opt);
    frame.load(scene.pts.data(), static_cast<int>(scene.pts.size()), model.max_pair_mm + cfg.t_mm);
    SearchResult fast, ref;
    SearchStats st;
    const bool f1 = search.run(model, frame, fast, st);
    const bool f2 = exhaustive_search(model, frame, cfg, ref);
    ASSERT_EQ(f1, f2) << "trial " << trial;
    if (!f1) continue;
    ++found;
    EXPECT_EQ(fast.m, ref.m) << "trial " << trial;
    EXPECT_EQ(fast.point_of_marker, ref.point_of_marker) << "trial " << trial;
    EXPECT_NEAR(fast.score, ref.score, 1e-9) << "trial " << trial;
    // The winner of Eq. 1 may be a coincidence (strays) when a rival is close: only a
    // unique winner is an identity the Identifier reports.
    if (fast.unique(cfg.ambiguity_ratio)) {
      ++unique;
      EXPECT_TRUE(test::identity_correct(
          scene, 0,
          BodyPose{true, false, false, fast.T_world_body, fast.m, 0, 0, fast.point_of_marker}))
          << "trial " << trial;
    }
  }
  EXPECT_GT(unique, trials * 9 / 10);
  EXPECT_EQ(found, trials);
}

// Two points sharing a blob in one camera: a solution uses at most one of them.
// The rival (runner-up pass) always contradicts the winner: a marker on another point
// (farther than a ball's diameter: nearer, it is the same ball measured twice), or a
// point on another marker, or extra markers that cannot join the winner's (the union not
// rigidly consistent). Solutions that agree wherever both assign and together are one
// solution, such as two 4-marker solutions of a 5-marker target that complete each
// other, tell the same identities and are never each other's rival (before: any two
// solutions of which neither was a subset of the other were rivals, and the body was
// dropped as ambiguous).
TEST(TargetSearch, RivalAlwaysContradictsTheWinner) {
  std::mt19937_64 rng(23);
  IdentifyConfig cfg;
  const double diameter_mm = 12.0;
  FramePoints frame(cfg.max_points);
  TargetSearch search(cfg, diameter_mm);
  int rivals = 0, complements = 0;
  for (int trial = 0; trial < 300; ++trial) {
    TargetSet set;
    set.bodies.push_back(random_target(rng, 5, "a"));
    const TargetModel model = model_of(set.bodies[0]);
    const auto scene = make_scene(rng, set, SceneOptions{1.5, 10, true, 3, 300.0});
    frame.load(scene.pts.data(), static_cast<int>(scene.pts.size()), model.max_pair_mm + cfg.t_mm);
    SearchResult r;
    SearchStats st;
    if (!search.run(model, frame, r, st) || !std::isfinite(r.rival_score)) continue;
    ++rivals;
    bool contradicts = false, adds = false;
    for (int c = 0; c < model.k; ++c) {
      const int bp = r.point_of_marker[static_cast<std::size_t>(c)];
      const int rp = r.rival_point_of_marker[static_cast<std::size_t>(c)];
      if (rp < 0 || rp == bp) continue;
      if (bp >= 0 && (frame.X(bp) - frame.X(rp)).norm() >= diameter_mm) contradicts = true;
      for (int a = 0; a < model.k; ++a)
        contradicts =
            contradicts || (a != c && r.point_of_marker[static_cast<std::size_t>(a)] == rp);
      adds = adds || bp < 0;
    }
    if (!contradicts && adds) {
      // Complementary: a rival only if the two cannot be one solution.
      ++complements;
      FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
      int u = 0;
      for (int c = 0; c < model.k; ++c) {
        int p = r.point_of_marker[static_cast<std::size_t>(c)];
        if (p < 0) p = r.rival_point_of_marker[static_cast<std::size_t>(c)];
        if (p < 0) continue;
        src.col(u) = model.M_body[static_cast<std::size_t>(c)];
        dst.col(u) = frame.X(p);
        ++u;
      }
      contradicts = fit_rigid(src, dst, u).max_sq_mm2 >= cfg.t_mm * cfg.t_mm;
    }
    EXPECT_TRUE(contradicts) << "trial " << trial;
  }
  EXPECT_GT(rivals, 10);  // the property was exercised
  std::printf("rivals %d, complementary %d\n", rivals, complements);
}

TEST(TargetSearch, MutuallyExclusiveCandidatesNotBothUsed) {
  std::mt19937_64 rng(3);
  const MarkerTarget t = random_target(rng, 5, "a");
  const TargetModel model = model_of(t);
  IdentifyConfig cfg;
  Iso3 T = Iso3::Identity();
  T.linear() = test::random_rotation(rng);
  T.translation() = Vec3(10, 20, 1500);
  std::vector<MeasuredPoint> pts(5);
  for (int c = 0; c < 5; ++c) {
    pts[static_cast<std::size_t>(c)].X_world = T * t.markers_body[static_cast<std::size_t>(c)];
    pts[static_cast<std::size_t>(c)].blob_index = {static_cast<std::int16_t>(c),
                                                   static_cast<std::int16_t>(c)};
  }
  pts[4].blob_index[0] = 0;  // marker 4's point shares camera 0's blob with marker 0's point
  FramePoints frame(cfg.max_points);
  frame.load(pts.data(), 5, model.max_pair_mm + cfg.t_mm);
  EXPECT_TRUE(frame.exclusive(0, 4));
  SearchResult r, ref;
  SearchStats st;
  ASSERT_TRUE(TargetSearch(cfg).run(model, frame, r, st));
  EXPECT_EQ(r.m, 4);
  EXPECT_FALSE(r.point_of_marker[0] >= 0 && r.point_of_marker[4] >= 0);
  ASSERT_TRUE(exhaustive_search(model, frame, cfg, ref));
  EXPECT_EQ(ref.m, 4);
  // Without the shared blob all five are used.
  pts[4].blob_index[0] = 4;
  frame.load(pts.data(), 5, model.max_pair_mm + cfg.t_mm);
  ASSERT_TRUE(TargetSearch(cfg).run(model, frame, r, st));
  EXPECT_EQ(r.m, 5);
}

TEST(TargetSearch, NotFoundAmongStraysOnly) {
  std::mt19937_64 rng(5);
  const TargetModel model = model_of(random_target(rng, 5, "a"));
  IdentifyConfig cfg;
  std::vector<MeasuredPoint> pts(2);
  pts[0].X_world = Vec3(0, 0, 0);
  pts[1].X_world = Vec3(model.pairs_sorted[0].d_mm, 0, 0);
  FramePoints frame(cfg.max_points);
  frame.load(pts.data(), 2, model.max_pair_mm + cfg.t_mm);
  SearchResult r;
  SearchStats st;
  EXPECT_FALSE(TargetSearch(cfg).run(model, frame, r, st));
  EXPECT_GT(st.seeds, 0);  // a 2-matching exists but m >= 3 is impossible
}

TEST(IdentifyConfig, ValidationErrorsNameTheKey) {
  IdentifyConfig c;
  EXPECT_TRUE(validate_config(c).ok());
  c.t_mm = 0.0;
  auto e = validate_config(c);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("identify: t_mm:"), std::string::npos);
  c = IdentifyConfig{};
  c.best_pairs = 0;
  EXPECT_NE(validate_config(c).error().message.find("best_pairs"), std::string::npos);
  c = IdentifyConfig{};
  c.min_markers = 2;
  EXPECT_NE(validate_config(c).error().message.find("min_markers"), std::string::npos);
  c = IdentifyConfig{};
  c.max_points = kMaxPoints + 1;
  EXPECT_NE(validate_config(c).error().message.find("max_points"), std::string::npos);
  c = IdentifyConfig{};
  c.warm_min_markers = 2;
  EXPECT_NE(validate_config(c).error().message.find("warm_min_markers"), std::string::npos);
}

TEST(TargetModel, RejectsTooFewOrTooCloseMarkers) {
  MarkerTarget t;
  t.name = "x";
  t.markers_body = {Vec3(0, 0, 0), Vec3(50, 0, 0)};
  auto m = make_target_model(t, IdentifyConfig{}, "bodies[0] 'x'");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message.find("bodies[0] 'x'"), std::string::npos);
  t.markers_body = {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 50, 0), Vec3(2, 0, 0)};
  m = make_target_model(t, IdentifyConfig{}, "bodies[0] 'x'");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message.find("markers 0 and 3"), std::string::npos);
}

}  // namespace
}  // namespace mocap
