// Design: an owned 8-bit RGB raster for diagnostic pictures (the calibration report's
// coverage maps, the blob overlays of `mocap preview`), written as PNG by
// formats/png_writer.h. Setup/offline code: it allocates; set() clips to the image.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mocap {

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

}  // namespace mocap
