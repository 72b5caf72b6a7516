// Design: tests of BlobRefs (core/camera_set.h) on cameras beyond 8: the 32-bit camera
// mask (bit 31 included) follows every write (set, clear, assignment through [], the
// initialiser list), count / shares_blob / operator== / for_each agree with the dense
// entries, a copy round-trips, and the unseen entries read -1.
#include <gtest/gtest.h>

#include <vector>

#include "core/camera_set.h"

namespace mocap {
namespace {

TEST(BlobRefs, ThirtyTwoCamerasFitTheMask) {
  static_assert(kMaxCameras == 32);
  static_assert(kMaxNodeCameras == 8);
  BlobRefs r;
  EXPECT_EQ(r.mask(), 0u);
  EXPECT_EQ(r.count(), 0);
  r.set(31, 7);
  r.set(8, 0);
  r[17] = 300;
  EXPECT_EQ(r.mask(), (CameraMask{1} << 31) | (CameraMask{1} << 17) | (CameraMask{1} << 8));
  EXPECT_EQ(r.count(), 3);
  EXPECT_EQ(r[31], 7);
  EXPECT_EQ(r[17], 300);
  EXPECT_EQ(r[8], 0);
  for (int c = 0; c < kMaxCameras; ++c) {
    if (c != 8 && c != 17 && c != 31) {
      EXPECT_EQ(r[c], -1) << c;
    }
  }
  r[17] = -1;  // unseen again: the bit goes with it
  EXPECT_EQ(r.mask(), (CameraMask{1} << 31) | (CameraMask{1} << 8));
  r.clear(31);
  EXPECT_EQ(r.mask(), CameraMask{1} << 8);
  EXPECT_EQ(r.count(), 1);
  EXPECT_EQ(r[31], -1);
}

TEST(BlobRefs, CountAndForEachVisitEverySeenCameraInOrder) {
  BlobRefs r;
  for (int c = 0; c < kMaxCameras; c += 3) r.set(static_cast<std::size_t>(c), 100 + c);
  EXPECT_EQ(r.count(), 11);  // 0, 3, ..., 30
  std::vector<int> cams, blobs;
  r.for_each([&](int c, int b) {
    cams.push_back(c);
    blobs.push_back(b);
  });
  ASSERT_EQ(cams.size(), 11u);
  for (std::size_t k = 0; k < cams.size(); ++k) {
    EXPECT_EQ(cams[k], static_cast<int>(3 * k));
    EXPECT_EQ(blobs[k], 100 + cams[k]);
  }
  BlobRefs all;
  for (int c = 0; c < kMaxCameras; ++c) all.set(static_cast<std::size_t>(c), c);
  EXPECT_EQ(all.count(), 32);
  EXPECT_EQ(all.mask(), ~CameraMask{0});
}

TEST(BlobRefs, SharesABlobOnlyInACameraBothSaw) {
  BlobRefs a, b;
  a.set(3, 5);
  a.set(30, 9);
  b.set(30, 8);  // camera 30, another blob
  b.set(12, 9);  // blob 9, another camera
  EXPECT_FALSE(a.shares_blob(b));
  EXPECT_FALSE(b.shares_blob(a));
  b.set(31, 2);
  a.set(31, 2);  // camera 31, the same blob
  EXPECT_TRUE(a.shares_blob(b));
  EXPECT_TRUE(b.shares_blob(a));
  a.clear(31);
  EXPECT_FALSE(a.shares_blob(b));
}

TEST(BlobRefs, EqualityAndCopiesRoundTrip) {
  BlobRefs a{4, -1, 6};  // cameras 0 and 2
  EXPECT_EQ(a.mask(), 0b101u);
  a[20] = 1;
  a[31] = 2;
  const BlobRefs copy = a;
  EXPECT_EQ(copy, a);
  EXPECT_EQ(copy.mask(), a.mask());
  for (int c = 0; c < kMaxCameras; ++c) EXPECT_EQ(copy[c], a[c]) << c;
  BlobRefs rebuilt;  // the same views written in another order
  rebuilt[31] = 2;
  rebuilt[0] = 4;
  rebuilt[20] = 1;
  rebuilt[2] = 6;
  EXPECT_EQ(rebuilt, a);
  rebuilt[20] = 3;  // another blob
  EXPECT_FALSE(rebuilt == a);
  rebuilt[20] = -1;  // a camera fewer
  EXPECT_FALSE(rebuilt == a);
  BlobRefs assigned;
  assigned[9] = a[31];  // assignment between entries keeps the mask
  EXPECT_EQ(assigned.mask(), CameraMask{1} << 9);
  EXPECT_EQ(assigned[9], 2);
}

}  // namespace
}  // namespace mocap
