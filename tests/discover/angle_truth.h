// Design: test helper shared by the discover and walkthrough tests: joint angles found
// with a discovered model against the simulator's gt/angles.csv. The discovered body
// frames differ from the true ones, so a hinge is compared up to a constant offset and
// sign (found + true or found - true is constant), a ball joint through the
// frame-independent angle of R_rel(f) R_rel(f0)^T. Rows are matched by (type, frame).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/units.h"
#include "formats/csv_outputs.h"

namespace mocap::test {

inline void expect_true_angles(const std::vector<AngleRow>& found, const std::string& truth_csv,
                               std::size_t min_hinge_frames) {
  auto truth = read_angles_csv(truth_csv);
  ASSERT_TRUE(truth) << truth.error().message;
  std::map<std::pair<JointType, std::int64_t>, AngleRow> true_rows;
  for (const AngleRow& r : *truth) true_rows[{r.type, r.frame}] = r;
  std::vector<double> sum, diff;                // hinge: found +- true
  std::vector<std::pair<double, double>> ball;  // (found, true) angles from the first frame, deg
  const AngleRow* ball_f0 = nullptr;
  const AngleRow* ball_t0 = nullptr;
  for (const AngleRow& r : found) {
    auto it = true_rows.find({r.type, r.frame});
    if (it == true_rows.end()) continue;
    const AngleRow& t = it->second;
    if (r.type == JointType::kHinge) {
      sum.push_back(r.angles_deg.x() + t.angles_deg.x());
      diff.push_back(r.angles_deg.x() - t.angles_deg.x());
      continue;
    }
    if (ball_f0 == nullptr) {
      ball_f0 = &r;
      ball_t0 = &t;
    }
    ball.emplace_back(r.q_parent_child.angularDistance(ball_f0->q_parent_child) * kDegPerRad,
                      t.q_parent_child.angularDistance(ball_t0->q_parent_child) * kDegPerRad);
  }
  ASSERT_GE(diff.size(), min_hinge_frames);
  ASSERT_GE(ball.size(), min_hinge_frames);
  // Deviations from the mean offset, sorted. With the discovered targets the lower arm
  // lacks its rarely seen fifth marker: in a few frames its pose comes through the chain
  // from 2 markers, one of them partly hidden (docs/discover.md), so the bound is on 97 %
  // of the frames, with every frame within 3 deg.
  auto deviations = [](const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    std::vector<double> d;
    for (double x : v) d.push_back(std::abs(std::remainder(x - m, 360.0)));
    std::sort(d.begin(), d.end());
    return d;
  };
  auto p97 = [](const std::vector<double>& d) {
    return d[static_cast<std::size_t>(0.97 * static_cast<double>(d.size() - 1))];
  };
  const auto d_sum = deviations(sum), d_diff = deviations(diff);
  const auto& hinge = p97(d_sum) < p97(d_diff) ? d_sum : d_diff;  // the axis sign is free
  EXPECT_LT(p97(hinge), 0.5);
  EXPECT_LT(hinge.back(), 3.0);
  std::vector<double> d_ball;
  for (const auto& [a, b] : ball) d_ball.push_back(std::abs(a - b));
  std::sort(d_ball.begin(), d_ball.end());
  EXPECT_LT(p97(d_ball), 0.5);
  EXPECT_LT(d_ball.back(), 3.0);
}

}  // namespace mocap::test
