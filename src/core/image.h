// Design: images as owned buffers (allocated once at setup) and non-owning views
// (what the hot path receives). 8-bit pixels are uint8; 16-bit pixels are stored
// as native-endian uint16 (PGM's big-endian bytes are swapped at load). Rows are
// contiguous with a stride in bytes so that driver-mapped buffers fit the same view.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mocap {

enum class PixelFormat : std::uint8_t { kMono8, kMono16 };

inline int bytes_per_pixel(PixelFormat f) noexcept { return f == PixelFormat::kMono8 ? 1 : 2; }

struct ImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride_bytes = 0;
  PixelFormat format = PixelFormat::kMono8;
  std::uint16_t maxval = 255;  // 255 for 8-bit; up to 65535 for 16-bit

  const std::uint8_t* row8(int y) const noexcept { return data + static_cast<std::ptrdiff_t>(y) * stride_bytes; }
  const std::uint16_t* row16(int y) const noexcept {
    return reinterpret_cast<const std::uint16_t*>(data + static_cast<std::ptrdiff_t>(y) * stride_bytes);
  }
  bool empty() const noexcept { return data == nullptr || width <= 0 || height <= 0; }
};

// An owned, tightly packed image. allocate() is setup-time; the hot path reuses it.
class Image {
 public:
  Image() = default;
  Image(int width, int height, PixelFormat format, std::uint16_t maxval) { allocate(width, height, format, maxval); }

  void allocate(int width, int height, PixelFormat format, std::uint16_t maxval) {
    width_ = width;
    height_ = height;
    format_ = format;
    maxval_ = maxval;
    pixels_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                       static_cast<std::size_t>(bytes_per_pixel(format)),
                   0);
  }

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  PixelFormat format() const noexcept { return format_; }
  std::uint16_t maxval() const noexcept { return maxval_; }
  void set_maxval(std::uint16_t m) noexcept { maxval_ = m; }
  int stride_bytes() const noexcept { return width_ * bytes_per_pixel(format_); }
  std::size_t size_bytes() const noexcept { return pixels_.size(); }

  std::uint8_t* data() noexcept { return pixels_.data(); }
  const std::uint8_t* data() const noexcept { return pixels_.data(); }
  std::uint8_t* row8(int y) noexcept { return pixels_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(stride_bytes()); }
  std::uint16_t* row16(int y) noexcept { return reinterpret_cast<std::uint16_t*>(row8(y)); }

  ImageView view() const noexcept {
    return ImageView{pixels_.data(), width_, height_, stride_bytes(), format_, maxval_};
  }

 private:
  std::vector<std::uint8_t> pixels_;
  int width_ = 0;
  int height_ = 0;
  PixelFormat format_ = PixelFormat::kMono8;
  std::uint16_t maxval_ = 255;
};

}  // namespace mocap
