// rt::CounterGroup: counters named where they are declared report themselves in
// declaration order; '#' becomes the camera index (per-camera arrays: one entry per camera
// of the rig; a one-camera group: its camera); values are the counters'; a group that
// overflows says so in its report instead of dropping a counter silently.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "rt/counter_group.h"

namespace mocap::rt {
namespace {

struct StageCounters {
  explicit StageCounters(int camera = -1) : group(camera) {}
  CounterGroup group;
  NamedCounter frames{group, "frames"};
  CameraCounters timeouts{group, "timeouts_cam#"};
  NamedCounter skipped{group, "detect#_skipped"};
};

TEST(CounterGroup, ReportsInDeclarationOrderWithCameraNames) {
  StageCounters k;
  k.frames.add(7);
  k.timeouts[0].add(1);
  k.timeouts[2].add(3);
  k.timeouts[5].add(9);  // beyond the rig's 3 cameras: not reported
  CounterReport out;
  k.group.report(3, out);
  const CounterReport want = {{"frames", 7},
                              {"timeouts_cam0", 1},
                              {"timeouts_cam1", 0},
                              {"timeouts_cam2", 3},
                              {"detect-1_skipped", 0}};
  EXPECT_EQ(out, want);
}

TEST(CounterGroup, OneCameraGroupNamesItsCamera) {
  StageCounters k(4);
  k.skipped.add(2);
  CounterReport out;
  k.group.report(8, out);
  ASSERT_EQ(out.size(), 1u + 8u + 1u);
  EXPECT_EQ(out.back(), (std::pair<std::string, std::uint64_t>{"detect4_skipped", 2}));
}

TEST(CounterGroup, OverflowIsReportedNotSilent) {
  auto group = std::make_unique<CounterGroup>();
  std::vector<std::unique_ptr<NamedCounter>> many;
  for (std::size_t i = 0; i < CounterGroup::kCapacity + 1; ++i)
    many.push_back(std::make_unique<NamedCounter>(*group, "c"));
  CounterReport out;
  group->report(2, out);
  ASSERT_EQ(out.size(), CounterGroup::kCapacity + 1);
  EXPECT_EQ(out.back().first, "counter_group_overflow");
}

TEST(CounterName, ReplacesEveryHash) {
  EXPECT_EQ(counter_name("a#b#", 12), "a12b12");
  EXPECT_EQ(counter_name("plain", 3), "plain");
}

}  // namespace
}  // namespace mocap::rt
