// FramePairer: in-order and out-of-order arrival, sequence gaps, one camera stalled,
// timestamp pairing within tolerance, every dropped frame handed back exactly once,
// and no allocation per frame.
#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

#include "hal/frame_pairer.h"
#include "tests/support/alloc_counter.h"

namespace mocap::hal {
namespace {

struct Harness {
  FramePairer pairer;
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs;  // keys (cam0, cam1)
  std::vector<std::pair<int, std::int64_t>> dropped;         // (camera, key)

  explicit Harness(PairerConfig cfg = {}) : pairer(*FramePairer::create(cfg)) {}
  void push(int cam, std::int64_t key) {
    FramePair p;
    // The handle encodes camera and key so that hand-backs can be checked.
    const PairEntry e{key, static_cast<std::uint32_t>(cam * 100000 + key % 100000)};
    if (pairer.push(cam, e, p, [&](int c, const PairEntry& d) {
          EXPECT_EQ(d.handle, static_cast<std::uint32_t>(c * 100000 + d.key % 100000));
          dropped.emplace_back(c, d.key);
        })) {
      EXPECT_EQ(p.cam[0].handle, static_cast<std::uint32_t>(p.cam[0].key % 100000));
      EXPECT_EQ(p.cam[1].handle, static_cast<std::uint32_t>(100000 + p.cam[1].key % 100000));
      pairs.emplace_back(p.cam[0].key, p.cam[1].key);
    }
  }
};

using Pairs = std::vector<std::pair<std::int64_t, std::int64_t>>;
using Drops = std::vector<std::pair<int, std::int64_t>>;

TEST(FramePairer, CreateValidates) {
  EXPECT_FALSE(FramePairer::create({-1, 8}).ok());
  EXPECT_FALSE(FramePairer::create({0, 0}).ok());
  EXPECT_TRUE(FramePairer::create({0, 1}).ok());
}

TEST(FramePairer, AlternatingCamerasPairEveryFrame) {
  Harness h;
  for (int s = 0; s < 5; ++s) {
    h.push(0, s);
    h.push(1, s);
  }
  EXPECT_EQ(h.pairs, (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}}));
  EXPECT_TRUE(h.dropped.empty());
  EXPECT_EQ(h.pairer.counters().pairs.get(), 5u);
  EXPECT_EQ(h.pairer.pending(0) + h.pairer.pending(1), 0u);
}

TEST(FramePairer, OneCameraRunsAheadOutOfOrder) {
  Harness h;
  for (int s = 0; s < 4; ++s) h.push(1, s);  // camera 1 delivers four frames first
  EXPECT_EQ(h.pairer.pending(1), 4u);
  h.push(0, 0);
  h.push(0, 1);
  h.push(1, 4);
  h.push(0, 2);
  h.push(0, 3);
  h.push(0, 4);
  EXPECT_EQ(h.pairs, (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}}));
  EXPECT_TRUE(h.dropped.empty());
}

TEST(FramePairer, GapsDropTheUnmatchedFrame) {
  Harness h;
  // Camera 0 lost frame 2, camera 1 lost frame 4.
  for (int s : {0, 1, 3, 4, 5}) h.push(0, s);
  for (int s : {0, 1, 2, 3, 5}) h.push(1, s);
  EXPECT_EQ(h.pairs, (Pairs{{0, 0}, {1, 1}, {3, 3}, {5, 5}}));
  EXPECT_EQ(h.dropped, (Drops{{1, 2}, {0, 4}}));
  EXPECT_EQ(h.pairer.counters().unmatched[0].get(), 1u);
  EXPECT_EQ(h.pairer.counters().unmatched[1].get(), 1u);
  EXPECT_EQ(h.pairer.pending(0) + h.pairer.pending(1), 0u);
}

TEST(FramePairer, StalledCameraOverflowsTheOtherQueue) {
  Harness h(PairerConfig{0, 3});
  h.push(0, 0);
  h.push(1, 0);
  for (int s = 1; s <= 10; ++s) h.push(0, s);  // camera 1 stalls
  EXPECT_EQ(h.pairer.pending(0), 3u);
  EXPECT_EQ(h.pairer.counters().overflow[0].get(), 7u);  // frames 1..7 dropped, oldest first
  ASSERT_EQ(h.dropped.size(), 7u);
  EXPECT_EQ(h.dropped.front(), (std::pair<int, std::int64_t>{0, 1}));
  EXPECT_EQ(h.dropped.back(), (std::pair<int, std::int64_t>{0, 7}));
  // Camera 1 comes back at frame 9: 8 is dead, 9 pairs, 10 waits.
  h.push(1, 9);
  EXPECT_EQ(h.pairs.back(), (std::pair<std::int64_t, std::int64_t>{9, 9}));
  EXPECT_EQ(h.dropped.back(), (std::pair<int, std::int64_t>{0, 8}));
  EXPECT_EQ(h.pairer.pending(0), 1u);
  // Camera 1 catches up: its frame 10 pairs with the one waiting.
  h.push(1, 10);
  EXPECT_EQ(h.pairs.back(), (std::pair<std::int64_t, std::int64_t>{10, 10}));
}

TEST(FramePairer, LateFrameIsDroppedOnArrival) {
  Harness h;
  h.push(0, 5);
  h.push(1, 5);
  h.push(1, 6);
  h.push(0, 7);  // camera 0 skipped 6 -> camera 1's 6 is dead
  h.push(0, 6);  // arrives late: camera 1 is already at 6, but 6 was dropped
  EXPECT_EQ(h.pairs, (Pairs{{5, 5}}));
  EXPECT_EQ(h.dropped, (Drops{{1, 6}, {0, 6}}));
}

TEST(FramePairer, TimestampsPairWithinTolerance) {
  Harness h(PairerConfig{1'000'000, 8});  // 1 ms; frames every 10 ms
  const std::int64_t period = 10'000'000;
  h.push(0, 0 * period + 200'000);
  h.push(1, 0 * period - 300'000);
  h.push(1, 1 * period + 900'000);
  h.push(0, 1 * period);
  h.push(0, 2 * period);
  h.push(1, 2 * period + 1'500'000);  // too far: 2 ms apart -> both unpaired
  h.push(0, 3 * period);
  h.push(1, 3 * period + 10);
  ASSERT_EQ(h.pairs.size(), 3u);
  EXPECT_EQ(h.pairs[1], (std::pair<std::int64_t, std::int64_t>{period, period + 900'000}));
  EXPECT_EQ(h.pairs[2], (std::pair<std::int64_t, std::int64_t>{3 * period, 3 * period + 10}));
  EXPECT_EQ(h.dropped.size(), 2u);
  EXPECT_EQ(h.pairer.counters().unmatched[0].get() + h.pairer.counters().unmatched[1].get(), 2u);
}

TEST(FramePairer, EveryFrameIsPairedOrHandedBackOnce) {
  Harness h(PairerConfig{0, 16});
  // A pseudo-random schedule: each camera drops ~10% of its frames and the cameras
  // drift up to 6 frames apart.
  std::uint32_t rng = 12345;
  auto next = [&] { return rng = rng * 1103515245u + 12345u; };
  std::int64_t seq[2] = {0, 0};
  int offered[2] = {0, 0};
  while (seq[0] < 2000 || seq[1] < 2000) {
    int cam = static_cast<int>((next() >> 16) % 2);
    if (seq[cam] >= 2000 || (seq[cam] - seq[1 - cam] > 6 && seq[1 - cam] < 2000)) cam = 1 - cam;
    const std::int64_t s = seq[cam]++;
    if ((next() >> 16) % 10 == 0) continue;  // lost before the pairer
    h.push(cam, s);
    ++offered[cam];
  }
  std::vector<std::pair<int, std::int64_t>> flushed;
  h.pairer.flush([&](int c, const PairEntry& e) { flushed.emplace_back(c, e.key); });
  // Conservation: offered = paired + dropped + flushed, for each camera.
  for (int c = 0; c < 2; ++c) {
    std::size_t dropped_c = 0, flushed_c = 0;
    for (auto& d : h.dropped) dropped_c += d.first == c;
    for (auto& f : flushed) flushed_c += f.first == c;
    EXPECT_EQ(static_cast<std::size_t>(offered[c]), h.pairs.size() + dropped_c + flushed_c) << c;
  }
  // Pairs are exact and strictly increasing.
  for (std::size_t i = 0; i < h.pairs.size(); ++i) {
    EXPECT_EQ(h.pairs[i].first, h.pairs[i].second);
    if (i > 0) {
      EXPECT_GT(h.pairs[i].first, h.pairs[i - 1].first);
    }
  }
  // Each camera loses ~10%: ~81% of the frames can pair; the queues (16) cover the
  // drift (<= 7), so nothing else is lost.
  EXPECT_GT(h.pairs.size(), 1500u);
  EXPECT_EQ(h.pairer.counters().overflow[0].get() + h.pairer.counters().overflow[1].get(), 0u);
}

TEST(FramePairer, FourCamerasFormSetsAndDropIncompleteOnes) {
  auto pairer = FramePairer::create({0, 8, 4});
  ASSERT_TRUE(pairer.ok());
  EXPECT_TRUE(FramePairer::create({0, 8, 12}).ok());  // a rig of up to kMaxCameras (32)
  EXPECT_FALSE(FramePairer::create({0, 8, 33}).ok());
  EXPECT_FALSE(FramePairer::create({0, 8, 1}).ok());
  std::vector<std::pair<int, std::int64_t>> dropped;
  std::vector<std::int64_t> sets;
  std::size_t offered = 0;
  for (std::int64_t s = 0; s < 40; ++s) {
    for (int c : {2, 0, 3, 1}) {            // any arrival order within a sequence
      if (c == 3 && s % 10 == 4) continue;  // camera 3 misses every 10th frame
      FramePair p;
      ++offered;
      if (pairer->push(c, {s, static_cast<std::uint32_t>(c)}, p,
                       [&](int cam, const PairEntry& e) { dropped.emplace_back(cam, e.key); })) {
        for (int k = 0; k < 4; ++k) {
          EXPECT_EQ(p.cam[k].key, s);
          EXPECT_EQ(p.cam[k].handle, static_cast<std::uint32_t>(k));
        }
        sets.push_back(s);
      }
    }
  }
  EXPECT_EQ(sets.size(), 36u);  // 4 of 40 sequences lack camera 3
  // The other three cameras' frames of each incomplete sequence are dropped once camera 3
  // has passed them: 3 x 4 frames, each handed back exactly once.
  EXPECT_EQ(dropped.size(), 12u);
  for (const auto& d : dropped) EXPECT_EQ(d.second % 10, 4) << d.first;
  EXPECT_EQ(offered, 4 * sets.size() + dropped.size());
  EXPECT_EQ(pairer->counters().unmatched[3].get(), 0u);
  EXPECT_EQ(pairer->counters().unmatched[0].get(), 4u);
}

TEST(FramePairer, PushAllocatesNothing) {
  auto pairer = FramePairer::create({0, 4});
  ASSERT_TRUE(pairer.ok());
  std::uint64_t drops = 0;
  auto on_drop = [&](int, const PairEntry&) { ++drops; };
  test::AllocationScope scope;
  FramePair p;
  for (std::int64_t s = 0; s < 1000; ++s) {
    if (s % 7 != 0) pairer->push(0, {s, 0}, p, on_drop);
    if (s % 5 != 0) pairer->push(1, {s, 1}, p, on_drop);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(drops, 0u);
}

}  // namespace
}  // namespace mocap::hal
