// Tests of targets.yaml: exact round trip and every validation error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "formats/targets_yaml.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const char* kValidTargets = R"(marker_diameter: 12.0
bodies:
  - name: torso
    markers:
      - [0, 0, 0]
      - [60, 0, 0]
      - [0, 45, 0]
      - [10, 20, 30]
  - name: upper_arm
    markers:
      - [0, 0, 0]
      - [50, 0, 0]
      - [0, 0, 40]
)";

class TargetsYamlTest : public ::testing::Test {
 protected:
  test::TempDir dir{"targets_yaml"};
  std::string path = dir.file("targets.yaml");

  std::string error_of(const std::string& text) {
    test::write_file(path, text);
    auto r = load_targets(path);
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    return r.error().message;
  }
  static std::string valid_with(const std::string& from, const std::string& to) {
    std::string s = kValidTargets;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) s.replace(pos, from.size(), to);
    return s;
  }
};

TEST_F(TargetsYamlTest, LoadsTheSpecExample) {
  test::write_file(path, kValidTargets);
  auto r = load_targets(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->marker_diameter_mm, 12.0);
  ASSERT_EQ(r->bodies.size(), 2u);
  EXPECT_EQ(r->bodies[0].name, "torso");
  ASSERT_EQ(r->bodies[0].markers_body.size(), 4u);
  EXPECT_EQ(r->bodies[0].markers_body[3], Vec3(10, 20, 30));
  EXPECT_EQ(r->index_of("upper_arm"), 1);
  EXPECT_EQ(r->index_of("nope"), -1);
}

TEST_F(TargetsYamlTest, DiameterDefaultsTo12mm) {
  test::write_file(path, valid_with("marker_diameter: 12.0\n", ""));
  auto r = load_targets(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->marker_diameter_mm, 12.0);
}

TEST_F(TargetsYamlTest, RoundTripIsExact) {
  TargetSet set;
  set.marker_diameter_mm = 9.5;
  for (int b = 0; b < 3; ++b) {
    MarkerTarget t;
    t.name = "body_" + std::to_string(b);
    for (int m = 0; m < 4 + b; ++m) {
      t.markers_body.emplace_back(m * 31.7 + 1.0 / 3.0, -m * 17.13 + b / 7.0, m * m * 2.000001);
    }
    set.bodies.push_back(t);
  }
  ASSERT_TRUE(save_targets(path, set).ok());
  auto r = load_targets(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->marker_diameter_mm, set.marker_diameter_mm);
  ASSERT_EQ(r->bodies.size(), set.bodies.size());
  for (std::size_t b = 0; b < set.bodies.size(); ++b) {
    EXPECT_EQ(r->bodies[b].name, set.bodies[b].name);
    EXPECT_EQ(r->bodies[b].markers_body, set.bodies[b].markers_body);
  }
}

TEST_F(TargetsYamlTest, MissingBodies) {
  EXPECT_THAT(error_of("marker_diameter: 12\n"), HasSubstr(": bodies: missing key"));
}

TEST_F(TargetsYamlTest, EmptyBodies) {
  EXPECT_THAT(error_of("bodies: []\n"), HasSubstr("bodies: empty list"));
}

TEST_F(TargetsYamlTest, MissingName) {
  EXPECT_THAT(error_of(valid_with("  - name: upper_arm\n    markers:", "  - markers:")),
              HasSubstr("bodies[1].name: missing key"));
}

TEST_F(TargetsYamlTest, BadDiameter) {
  EXPECT_THAT(error_of(valid_with("marker_diameter: 12.0", "marker_diameter: -1")),
              HasSubstr("marker_diameter: must be > 0 mm, got -1"));
  EXPECT_THAT(error_of(valid_with("marker_diameter: 12.0", "marker_diameter: twelve")),
              HasSubstr("marker_diameter: expected a number, got 'twelve'"));
}

TEST_F(TargetsYamlTest, FewerThanThreeMarkers) {
  EXPECT_THAT(error_of(valid_with("      - [0, 0, 40]\n", "")),
              AllOf(HasSubstr("bodies[1].markers: body 'upper_arm' has 2 markers, at least 3")));
}

TEST_F(TargetsYamlTest, MarkerWithTwoCoordinates) {
  EXPECT_THAT(error_of(valid_with("[10, 20, 30]", "[10, 20]")),
              HasSubstr("bodies[0].markers[3]: expected 3 numbers, got 2"));
}

TEST_F(TargetsYamlTest, MarkerNotFinite) {
  EXPECT_THAT(error_of(valid_with("[10, 20, 30]", "[10, .nan, 30]")),
              HasSubstr("bodies[0].markers[3][1]: not a finite number"));
}

TEST_F(TargetsYamlTest, MarkersCloserThanDiameter) {
  EXPECT_THAT(
      error_of(valid_with("[10, 20, 30]", "[55, 3, 4]")),
      AllOf(HasSubstr("bodies[0].markers: markers 1 and 3 of body 'torso' are 7.071 mm apart"),
            HasSubstr("marker diameter 12.000 mm")));
}

TEST_F(TargetsYamlTest, DuplicateBodyNames) {
  EXPECT_THAT(error_of(valid_with("name: upper_arm", "name: torso")),
              HasSubstr("bodies[1].name: duplicate body name 'torso'"));
}

TEST_F(TargetsYamlTest, NameWithCommaRejected) {
  EXPECT_THAT(error_of(valid_with("name: upper_arm", "name: \"upper,arm\"")),
              HasSubstr("bodies[1].name: name 'upper,arm' contains"));
}

TEST_F(TargetsYamlTest, MarkersAsMapRejected) {
  EXPECT_THAT(error_of("bodies:\n  - name: a\n    markers: {x: 1}\n"),
              HasSubstr("bodies[0].markers: expected a list, got a map"));
}

}  // namespace
}  // namespace mocap
