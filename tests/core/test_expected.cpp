// Tests of Expected<T>/Error: values, errors and the one-line message format.
#include <gtest/gtest.h>

#include <memory>

#include "core/expected.h"

namespace mocap {
namespace {

Expected<int> parse_positive(int v) {
  if (v <= 0) return make_error("rig.yaml", "cameras[0].width", "must be positive, got " + std::to_string(v));
  return v;
}

TEST(Expected, HoldsValue) {
  auto r = parse_positive(3);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(*r, 3);
}

TEST(Expected, HoldsErrorWithFileKeyAndProblem) {
  auto r = parse_positive(-1);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "rig.yaml: cameras[0].width: must be positive, got -1");
  EXPECT_EQ(make_error("a.pgm", "", "empty file").message, "a.pgm: empty file");
}

TEST(Expected, MoveOnlyValuesAndVoid) {
  Expected<std::unique_ptr<int>> p(std::make_unique<int>(5));
  ASSERT_TRUE(p.ok());
  std::unique_ptr<int> owned = std::move(p).value();
  EXPECT_EQ(*owned, 5);
  Expected<void> ok;
  EXPECT_TRUE(ok.ok());
  Expected<void> bad = Error{"x"};
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "x");
}

}  // namespace
}  // namespace mocap
