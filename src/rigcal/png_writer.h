// Design: a minimal PNG encoder (8-bit RGB, no interlace, filter 0 on every row) for
// the calibration report's coverage images: the IHDR/IDAT/IEND chunks with zlib's
// compress() for the image data and crc32() for the chunk checksums.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"

namespace mocap::rigcal {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3, row-major
  RgbImage(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w * h) * 3, 0) {}
  void set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                    static_cast<std::size_t>(x)) *
                   3;
    rgb[i] = r;
    rgb[i + 1] = g;
    rgb[i + 2] = b;
  }
};

// The PNG file's bytes.
Expected<std::vector<std::uint8_t>> encode_png(const RgbImage& image);
Expected<void> write_png(const std::string& path, const RgbImage& image);

}  // namespace mocap::rigcal
