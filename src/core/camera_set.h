// Design: the camera count as a value. A rig has 2 to kMaxCameras (32) cameras; a camera
// node (`mocap node`) publishes at most kMaxNodeCameras (8) of them. Per-camera state of
// the real-time path is sized at setup from the rig's camera count (vectors, or small
// fixed arrays over kMaxCameras of scalars), of which the first camera_count entries are
// meaningful.
// BlobRefs is the one type that says which blob of each camera a 3D point was measured
// from (-1: that camera did not see it). It is used by stereo candidates, identified
// points and published results alike; every entry it does not set is -1, so a
// two-camera initialiser such as {3, 4} means "blob 3 of camera 0, blob 4 of camera 1,
// no other camera". Beside the dense per-camera indices it keeps a 32-bit camera mask
// (bit c: camera c saw the point), maintained by every write (set(), clear(), or
// assignment through operator[]), so that count(), shares_blob(), operator== and
// iteration over the seen cameras cost one step per camera that saw the point, not one
// per possible camera: a point of an 8-camera rig costs what it did when kMaxCameras
// was 8. The unseen entries always hold -1, so a read is one load with no test.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

namespace mocap {

// Cameras of a rig: at least kMinCameras (a stereo pair), at most kMaxCameras.
inline constexpr int kMinCameras = 2;
inline constexpr int kMaxCameras = 32;
// Cameras of one camera node (`mocap node`: capture + detection on one PC).
inline constexpr int kMaxNodeCameras = 8;
// The longest lead a central trigger to camera nodes may be posted with ahead of its
// instant (node.trigger_lead_us), and the longest a node waits for a trigger's instant.
inline constexpr std::int64_t kMaxTriggerLeadUs = 100'000;

// A set of cameras: bit c for camera c (c < kMaxCameras).
using CameraMask = std::uint32_t;
static_assert(kMaxCameras <= 32, "CameraMask holds one bit per camera in 32 bits");

class BlobRefs {
 public:
  using Array = std::array<std::int16_t, kMaxCameras>;

  // Assignment through operator[] on a non-const BlobRefs: keeps the mask in step.
  class Ref {
   public:
    constexpr operator std::int16_t() const noexcept { return refs_.index_[c_]; }
    constexpr Ref& operator=(int blob) noexcept {
      refs_.set(c_, blob);
      return *this;
    }
    constexpr Ref& operator=(const Ref& o) noexcept { return *this = static_cast<int>(o); }

   private:
    friend class BlobRefs;
    constexpr Ref(BlobRefs& refs, std::size_t c) noexcept : refs_(refs), c_(c) {}
    BlobRefs& refs_;
    std::size_t c_;
  };

  constexpr BlobRefs() noexcept { index_.fill(-1); }
  // Blob of camera 0, 1, ... in order; cameras after the list are unused (-1).
  constexpr BlobRefs(std::initializer_list<int> blobs) noexcept {
    index_.fill(-1);
    std::size_t c = 0;
    for (int b : blobs) {
      if (c >= index_.size()) break;
      set(c++, b);
    }
  }

  constexpr std::int16_t operator[](std::size_t c) const noexcept { return index_[c]; }
  constexpr std::int16_t operator[](int c) const noexcept {
    return index_[static_cast<std::size_t>(c)];
  }
  constexpr Ref operator[](std::size_t c) noexcept { return Ref(*this, c); }
  constexpr Ref operator[](int c) noexcept { return Ref(*this, static_cast<std::size_t>(c)); }

  // Camera c saw blob `blob` (a negative blob: camera c did not see the point).
  constexpr void set(std::size_t c, int blob) noexcept {
    if (blob < 0) {
      clear(c);
      return;
    }
    index_[c] = static_cast<std::int16_t>(blob);
    mask_ |= CameraMask{1} << c;
  }
  constexpr void clear(std::size_t c) noexcept {
    index_[c] = -1;
    mask_ &= ~(CameraMask{1} << c);
  }

  static constexpr std::size_t size() noexcept { return kMaxCameras; }

  // Cameras that saw the point: a table look-up per 8 cameras (std::popcount is a
  // library call on the baseline x86-64 this builds for).
  constexpr int count() const noexcept {
    CameraMask m = mask_;
    int n = 0;
    for (; m > 0xFFu; m >>= 8) n += kBits[m & 0xFFu];
    return n + kBits[m];
  }
  // Bit c set when camera c saw the point.
  constexpr CameraMask mask() const noexcept { return mask_; }
  // Whether the two points use the same blob of some camera (mutually exclusive).
  constexpr bool shares_blob(const BlobRefs& o) const noexcept {
    for (CameraMask m = mask_ & o.mask_; m != 0; m &= m - 1) {
      const auto c = static_cast<std::size_t>(std::countr_zero(m));
      if (index_[c] == o.index_[c]) return true;
    }
    return false;
  }
  // Calls f(camera, blob) for every camera that saw the point, in camera order.
  template <typename F>
  constexpr void for_each(F&& f) const noexcept(noexcept(f(0, 0))) {
    for (CameraMask m = mask_; m != 0; m &= m - 1) {
      const int c = std::countr_zero(m);
      f(c, static_cast<int>(index_[static_cast<std::size_t>(c)]));
    }
  }

  // Equal cameras with equal blobs (the unseen entries are -1 in both).
  friend constexpr bool operator==(const BlobRefs& a, const BlobRefs& b) noexcept {
    if (a.mask_ != b.mask_) return false;
    for (CameraMask m = a.mask_; m != 0; m &= m - 1) {
      const auto c = static_cast<std::size_t>(std::countr_zero(m));
      if (a.index_[c] != b.index_[c]) return false;
    }
    return true;
  }

  // Every camera's entry (-1: unseen), e.g. for hashing (stereo/blob_set_index.h).
  const Array& indices() const noexcept { return index_; }

 private:
  static constexpr std::array<std::uint8_t, 256> kBits = [] {
    std::array<std::uint8_t, 256> t{};
    for (std::size_t v = 0; v < t.size(); ++v)
      t[v] =
          static_cast<std::uint8_t>((v & 1u) + (v >> 1 & 1u) + (v >> 2 & 1u) + (v >> 3 & 1u) +
                                    (v >> 4 & 1u) + (v >> 5 & 1u) + (v >> 6 & 1u) + (v >> 7 & 1u));
    return t;
  }();

  Array index_{};
  CameraMask mask_ = 0;
};

}  // namespace mocap
