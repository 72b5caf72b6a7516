// Design: a minimal PNG encoder (8-bit RGB, no interlace, filter 0 on every row) for
// the calibration report's coverage images and `mocap preview`'s blob overlays (moved
// here from src/rigcal so that modules below rigcal can use it): the IHDR/IDAT/IEND chunks with
// zlib's compress() for the image data and crc32() for the chunk checksums.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/rgb_image.h"

namespace mocap {

// The PNG file's bytes.
Expected<std::vector<std::uint8_t>> encode_png(const RgbImage& image);
Expected<void> write_png(const std::string& path, const RgbImage& image);

}  // namespace mocap
