// Design: wand labelling: order of the markers (either direction of the wand in the
// image), strays tolerated, missing markers, a stray on the wand's line, the wrong
// spacing, too many blobs.
#include <gtest/gtest.h>

#include "rigcal/wand_labeler.h"
#include "tests/rigcal/rigcal_fixture.h"

namespace mocap::rigcal {
namespace {

std::vector<Vec2> wand_points(const Vec2& a, const Vec2& b, double r) {
  return {a, a + r * (b - a), b};
}

TEST(WandLabeler, LabelsBothDirectionsWithStrays) {
  std::vector<int> order;
  auto pts = wand_points(Vec2(100, 100), Vec2(400, 250), 110.0 / 300.0);
  // Blob order shuffled, plus two strays away from the line.
  std::vector<Vec2> blobs = {Vec2(700, 50), pts[2], pts[0], Vec2(300, 600), pts[1]};
  ASSERT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, blobs, order),
            LabelStatus::kOk);
  EXPECT_EQ(order, (std::vector<int>{2, 4, 1}));
  // The wand pointing the other way in the image.
  pts = wand_points(Vec2(600, 500), Vec2(300, 120), 110.0 / 300.0);
  ASSERT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, pts, order), LabelStatus::kOk);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
}

TEST(WandLabeler, PerspectiveShiftWithinTolerance) {
  std::vector<int> order;
  auto pts = wand_points(Vec2(100, 100), Vec2(400, 100), 110.0 / 300.0 + 0.05);
  pts[1].y() += 1.0;
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, pts, order), LabelStatus::kOk);
}

TEST(WandLabeler, Rejections) {
  std::vector<int> order;
  const auto pts = wand_points(Vec2(100, 100), Vec2(400, 250), 110.0 / 300.0);
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{},
                       std::vector<Vec2>{pts[0], pts[2]}, order),
            LabelStatus::kTooFewBlobs);
  // A stray close to the wand's line between its markers: unsafe.
  auto on_line = pts;
  on_line.push_back(pts[0] + 0.8 * (pts[2] - pts[0]) + Vec2(0.5, -0.5));
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, on_line, order),
            LabelStatus::kAmbiguous);
  // Wrong spacing: the middle marker at the centre.
  const auto mid = wand_points(Vec2(100, 100), Vec2(400, 250), 0.5);
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, mid, order),
            LabelStatus::kNoWand);
  // Not collinear.
  auto bent = pts;
  bent[1] += Vec2(-8.0, 8.0);
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, bent, order),
            LabelStatus::kNoWand);
  // Two wands.
  auto two = pts;
  for (const Vec2& p : wand_points(Vec2(600, 500), Vec2(900, 600), 110.0 / 300.0)) two.push_back(p);
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, two, order),
            LabelStatus::kAmbiguous);
  std::vector<Vec2> many(20, Vec2::Zero());
  for (int i = 0; i < 20; ++i) many[static_cast<std::size_t>(i)] = Vec2(37.0 * i, 11.0 * (i % 5));
  EXPECT_EQ(label_wand(mocap::test::test_wand(), WandLabelConfig{}, many, order),
            LabelStatus::kTooManyBlobs);
  EXPECT_STREQ(label_status_name(LabelStatus::kAmbiguous), "ambiguous");
}

TEST(WandLabeler, FourMarkerWand) {
  WandSpec w;
  w.markers_mm = {0.0, 80.0, 200.0, 380.0};
  std::vector<Vec2> pts;
  for (double s : w.markers_mm) pts.push_back(Vec2(500, 100) + s / 380.0 * Vec2(-200, 450));
  std::swap(pts[0], pts[3]);
  std::vector<int> order;
  ASSERT_EQ(label_wand(w, WandLabelConfig{}, pts, order), LabelStatus::kOk);
  EXPECT_EQ(order, (std::vector<int>{3, 1, 2, 0}));
}

}  // namespace
}  // namespace mocap::rigcal
