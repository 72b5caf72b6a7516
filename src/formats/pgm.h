// Design: binary PGM (P5) reader/writer. 8-bit (maxval <= 255) and 16-bit
// (256..65535, big-endian on disk, native uint16 in memory); '#' comments allowed in
// the header. Errors: empty file, wrong magic, bad or out-of-range header fields,
// maxval 0 or > 65535, truncated pixel data, size differing from what is expected.
// read_pgm reuses the Image's buffer when the size and format already match, so a
// replay loop that reads into the same Image does not allocate per frame.
#pragma once

#include <string>

#include "core/expected.h"
#include "core/image.h"

namespace mocap {

// Largest accepted image width or height (PGM files and rig.yaml), in pixels.
inline constexpr int kMaxImageSidePx = 16384;

Expected<void> read_pgm(const std::string& path, Image& out);
// As read_pgm, but fails with "<path>: size WxH differs from the rig's WxH" when the
// image size is not the expected one.
Expected<void> read_pgm_expect(const std::string& path, int expected_width, int expected_height,
                               Image& out);
Expected<void> write_pgm(const std::string& path, const ImageView& image);

}  // namespace mocap
