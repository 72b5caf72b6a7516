// Design: the one fixed-capacity list of the real-time path (blobs of a frame, 3D point
// candidates, ...). The capacity is set once at setup (set_capacity allocates); after
// that the hot path only clears, appends and reads: push_back never allocates, returns
// false when the list is full and counts the refused element in overflow() (since the
// last clear()), so a caller that does not keep its own counter still sees what did not
// fit. Everything but set_capacity is noexcept. Elements are read by index, by range-for
// or as a std::span over the filled part. Index is the caller's index type: std::size_t
// for lists indexed like containers, int where indices travel in int fields (blob and
// point indices of BlobRefs / MeasuredPoint).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

namespace mocap {

template <class T, class Index = std::size_t>
class BoundedList {
  static_assert(std::is_integral_v<Index>, "BoundedList: Index must be an integer type");

 public:
  using value_type = T;
  using size_type = Index;

  BoundedList() = default;
  explicit BoundedList(Index capacity) { set_capacity(capacity); }

  // Setup only (allocates): room for `capacity` elements (a negative one is 0); clears.
  void set_capacity(Index capacity) {
    storage_.assign(capacity > 0 ? static_cast<std::size_t>(capacity) : 0, T{});
    clear();
  }

  void clear() noexcept {
    size_ = 0;
    overflow_ = 0;
  }
  // Appends when there is room; otherwise writes nothing, counts it and returns false.
  bool push_back(const T& value) noexcept {
    if (full()) {
      ++overflow_;
      return false;
    }
    storage_[static_cast<std::size_t>(size_++)] = value;
    return true;
  }

  Index size() const noexcept { return size_; }
  Index capacity() const noexcept { return static_cast<Index>(storage_.size()); }
  bool empty() const noexcept { return size_ == 0; }
  bool full() const noexcept { return static_cast<std::size_t>(size_) >= storage_.size(); }
  // Elements refused by push_back since the last clear() (or set_capacity).
  std::uint64_t overflow() const noexcept { return overflow_; }

  T& operator[](Index i) noexcept { return storage_[static_cast<std::size_t>(i)]; }
  const T& operator[](Index i) const noexcept { return storage_[static_cast<std::size_t>(i)]; }
  T* begin() noexcept { return storage_.data(); }
  T* end() noexcept { return storage_.data() + static_cast<std::size_t>(size_); }
  const T* begin() const noexcept { return storage_.data(); }
  const T* end() const noexcept { return storage_.data() + static_cast<std::size_t>(size_); }
  std::span<T> span() noexcept { return {begin(), end()}; }
  std::span<const T> span() const noexcept { return {begin(), end()}; }

 private:
  std::vector<T> storage_;
  Index size_ = 0;
  std::uint64_t overflow_ = 0;
};

}  // namespace mocap
