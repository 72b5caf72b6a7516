// Design: the camera count as a value. A rig has 2 to kMaxCameras cameras; every
// per-camera quantity of the real-time path is a fixed array over kMaxCameras (no
// allocation), of which the first camera_count entries are meaningful.
// BlobRefs is the one type that says which blob of each camera a 3D point was measured
// from (-1: that camera did not see it). It is used by stereo candidates, identified
// points and published results alike; every entry it does not set is -1, so a
// two-camera initialiser such as {3, 4} means "blob 3 of camera 0, blob 4 of camera 1,
// no other camera".
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

namespace mocap {

// Cameras of a rig: at least kMinCameras (a stereo pair), at most kMaxCameras.
inline constexpr int kMinCameras = 2;
inline constexpr int kMaxCameras = 8;

class BlobRefs {
 public:
  using Array = std::array<std::int16_t, kMaxCameras>;

  constexpr BlobRefs() noexcept { index_.fill(-1); }
  // Blob of camera 0, 1, ... in order; cameras after the list are unused (-1).
  constexpr BlobRefs(std::initializer_list<int> blobs) noexcept {
    index_.fill(-1);
    std::size_t c = 0;
    for (int b : blobs) {
      if (c >= index_.size()) break;
      index_[c++] = static_cast<std::int16_t>(b);
    }
  }

  constexpr std::int16_t& operator[](std::size_t c) noexcept { return index_[c]; }
  constexpr std::int16_t operator[](std::size_t c) const noexcept { return index_[c]; }
  constexpr std::int16_t& operator[](int c) noexcept { return index_[static_cast<std::size_t>(c)]; }
  constexpr std::int16_t operator[](int c) const noexcept {
    return index_[static_cast<std::size_t>(c)];
  }
  static constexpr std::size_t size() noexcept { return kMaxCameras; }
  constexpr auto begin() noexcept { return index_.begin(); }
  constexpr auto end() noexcept { return index_.end(); }
  constexpr auto begin() const noexcept { return index_.begin(); }
  constexpr auto end() const noexcept { return index_.end(); }

  // Cameras that saw the point.
  constexpr int count() const noexcept {
    return static_cast<int>(
        std::count_if(index_.begin(), index_.end(), [](std::int16_t b) { return b >= 0; }));
  }
  // Bit c set when camera c saw the point.
  constexpr std::uint8_t mask() const noexcept {
    unsigned m = 0;
    for (std::size_t c = 0; c < index_.size(); ++c)
      if (index_[c] >= 0) m |= 1u << c;
    return static_cast<std::uint8_t>(m);
  }
  // Whether the two points use the same blob of some camera (mutually exclusive).
  constexpr bool shares_blob(const BlobRefs& o) const noexcept {
    for (std::size_t c = 0; c < index_.size(); ++c)
      if (index_[c] >= 0 && index_[c] == o.index_[c]) return true;
    return false;
  }

  friend constexpr bool operator==(const BlobRefs&, const BlobRefs&) noexcept = default;

 private:
  Array index_{};
};

static_assert(kMaxCameras <= 8, "BlobRefs::mask() holds one bit per camera in 8 bits");

}  // namespace mocap
