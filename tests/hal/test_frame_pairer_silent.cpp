// FramePairer's silent cameras (issue 29, hardware-triggered camera nodes): a camera the
// others' frames waited for past its bound is left out of their sets (kAbsentHandle,
// counted), the next sets complete at once, and it is used again from its next frame
// with a higher key; keys that start over keep it silent; the wait survives the others'
// queue overflowing; without a bound (or with nobody waiting) nothing is ever declared
// silent; no allocation.
#include <gtest/gtest.h>

#include <vector>

#include "hal/frame_pairer.h"
#include "tests/support/alloc_counter.h"

namespace mocap::hal {
namespace {

// Three cameras; camera 2 (a node's) is silent after 100 ns of waiting.
struct SilentPairerRig {
  FramePairer pairer;
  std::vector<FramePair> sets;
  std::vector<std::pair<int, std::int64_t>> dropped;

  explicit SilentPairerRig(std::int64_t bound = 100, std::uint32_t max_pending = 8)
      : pairer(*FramePairer::create(config(bound, max_pending))) {}
  static PairerConfig config(std::int64_t bound, std::uint32_t max_pending) {
    PairerConfig c{0, max_pending, 3, {}};
    c.silent_after_ns[2] = bound;
    return c;
  }
  void push(int cam, std::int64_t key, std::int64_t now) {
    FramePair p;
    if (pairer.push(
            cam, {key, static_cast<std::uint32_t>(cam)}, p,
            [&](int c, const PairEntry& e) { dropped.emplace_back(c, e.key); }, now))
      sets.push_back(p);
  }
  int expire(std::int64_t now) {
    int n = 0;
    FramePair p;
    while (pairer.expire(now, p)) {
      sets.push_back(p);
      ++n;
    }
    return n;
  }
  // The key of set i, and whether camera 2 took part in it.
  std::int64_t key(std::size_t i) const { return sets[i].cam[0].key; }
  bool has2(std::size_t i) const { return sets[i].cam[2].handle != kAbsentHandle; }
};

TEST(FramePairerSilent, ASilentCameraIsLeftOutAfterItsBoundAndUsedAgainWhenBack) {
  SilentPairerRig r;
  for (int c : {0, 1, 2}) r.push(c, 0, 1);  // a full set
  ASSERT_EQ(r.sets.size(), 1u);
  EXPECT_TRUE(r.has2(0));
  r.push(0, 1, 10);  // camera 2 goes quiet: frame 1 waits for it from t = 10
  r.push(1, 1, 11);
  EXPECT_EQ(r.expire(109), 0);  // within the bound: still waited for
  EXPECT_FALSE(r.pairer.silent(2));
  EXPECT_EQ(r.pairer.next_silence_ns(), 110);
  EXPECT_EQ(r.expire(110), 1);  // the bound: frame 1 completes without camera 2
  ASSERT_EQ(r.sets.size(), 2u);
  EXPECT_EQ(r.key(1), 1);
  EXPECT_EQ(r.sets[1].cam[1].key, 1);
  EXPECT_FALSE(r.has2(1));
  EXPECT_TRUE(r.pairer.silent(2));
  r.push(0, 2, 120);  // silent: frame 2 completes at once
  r.push(1, 2, 121);
  ASSERT_EQ(r.sets.size(), 3u);
  EXPECT_FALSE(r.has2(2));
  r.push(2, 3, 130);  // back (a key above its last): waited for again
  EXPECT_FALSE(r.pairer.silent(2));
  r.push(0, 3, 131);
  r.push(1, 3, 132);
  ASSERT_EQ(r.sets.size(), 4u);
  EXPECT_TRUE(r.has2(3));
  EXPECT_EQ(r.key(3), 3);
  const PairerCounters& k = r.pairer.counters();
  EXPECT_EQ(k.silent[2].get(), 1u);
  EXPECT_EQ(k.absent[2].get(), 2u);
  EXPECT_EQ(k.partial.get(), 2u);
  EXPECT_EQ(k.absent[0].get() + k.absent[1].get(), 0u);
  EXPECT_TRUE(r.dropped.empty());
}

TEST(FramePairerSilent, KeysThatStartOverKeepTheCameraSilent) {
  SilentPairerRig r;
  for (std::int64_t s = 0; s < 50; ++s)
    for (int c : {0, 1, 2}) r.push(c, s, 1 + s);
  r.push(0, 50, 100);
  r.push(1, 50, 100);
  EXPECT_EQ(r.expire(200), 1);
  r.push(2, 0, 210);  // restarted: its numbers start at 0 again
  EXPECT_TRUE(r.pairer.silent(2));
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0], (std::pair<int, std::int64_t>{2, 0}));
  r.push(0, 51, 220);  // the others go on without it, no new wait
  r.push(1, 51, 220);
  EXPECT_EQ(r.sets.size(), 52u);
  EXPECT_FALSE(r.has2(51));
  EXPECT_EQ(r.pairer.counters().unmatched[2].get(), 1u);
}

// A wait longer than the queues hold: the others' oldest frames overflow, the wait
// still counts from the first frame that waited, and what is pending then completes.
TEST(FramePairerSilent, TheWaitOutlastsTheOthersQueueOverflow) {
  SilentPairerRig r(100, 2);
  for (std::int64_t s = 0; s < 6; ++s) {
    r.push(0, s, 10 + 20 * s);
    r.push(1, s, 10 + 20 * s);
  }
  EXPECT_TRUE(r.sets.empty());
  EXPECT_GT(r.pairer.counters().overflow[0].get(), 0u);
  EXPECT_EQ(r.expire(110), 2);  // frames 4 and 5 (the queues' 2), oldest first
  ASSERT_EQ(r.sets.size(), 2u);
  EXPECT_EQ(r.key(0), 4);
  EXPECT_EQ(r.key(1), 5);
  EXPECT_EQ(r.pairer.pending(0) + r.pairer.pending(1), 0u);
}

TEST(FramePairerSilent, NothingIsInventedWithoutABoundOrWithoutAWaitingFrame) {
  SilentPairerRig unbounded(0);
  unbounded.push(0, 1, 10);
  unbounded.push(1, 1, 10);
  EXPECT_EQ(unbounded.expire(1'000'000'000), 0);
  EXPECT_FALSE(unbounded.pairer.silent(2));
  SilentPairerRig quiet;  // every camera silent: nobody waits, no set
  EXPECT_EQ(quiet.expire(1'000'000'000), 0);
  EXPECT_FALSE(quiet.pairer.silent(2));
  // A camera the bounded one waits for is not declared silent (no bound of its own).
  SilentPairerRig other;
  other.push(2, 1, 10);
  other.push(0, 1, 10);
  EXPECT_EQ(other.expire(1'000'000'000), 0);
  EXPECT_TRUE(other.sets.empty());
}

TEST(FramePairerSilent, TimestampsPairAgainAfterTheNodeCameBack) {
  PairerConfig c{1000, 8, 3, {}};
  c.silent_after_ns[2] = 50'000;
  auto pairer = FramePairer::create(c);
  ASSERT_TRUE(pairer.ok());
  int full = 0, partial = 0;
  auto on_drop = [](int, const PairEntry&) {};
  for (std::int64_t f = 0; f < 30; ++f) {
    const std::int64_t t = f * 10'000;  // 100 kHz of keys, the arrival time = the key
    const bool node_up = f < 10 || f >= 20;
    FramePair p;
    for (int cam = 0; cam < 3; ++cam) {
      if (cam == 2 && !node_up) continue;
      if (pairer->push(cam, {t + cam * 100, 0}, p, on_drop, t + cam))
        (p.cam[2].handle == kAbsentHandle ? partial : full)++;
    }
    while (pairer->expire(t + 5, p)) (p.cam[2].handle == kAbsentHandle ? partial : full)++;
  }
  // The 10 frames of the outage complete without camera 2 (the first 5 once the bound
  // passed), and so does the first frame after it: camera 2's frame came after the
  // others had completed it (dropped, unmatched); from then on every set is full.
  EXPECT_EQ(full, 19);
  EXPECT_EQ(partial, 11);
  EXPECT_EQ(pairer->counters().silent[2].get(), 1u);
  EXPECT_EQ(pairer->counters().unmatched[2].get(), 1u);
}

TEST(FramePairerSilent, ExpireAllocatesNothing) {
  SilentPairerRig r;
  r.sets.reserve(4000);
  r.dropped.reserve(4000);
  test::AllocationScope scope;
  for (std::int64_t s = 0; s < 1000; ++s) {
    r.push(0, s, 10 * s + 1);
    r.push(1, s, 10 * s + 1);
    if (s % 100 < 50) r.push(2, s, 10 * s + 2);
    r.expire(10 * s + 5);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(r.pairer.counters().partial.get(), 0u);
}

}  // namespace
}  // namespace mocap::hal
