// Design: the allocation-free core of the PGM reader (internal to mocap_formats), taking
// a C path so that callers such as Recording::load_frame can build the path in a stack
// buffer. On success with an Image of the right size and format it performs no heap
// allocation: open/fstat/read straight into the Image's buffer. Errors allocate (they
// build the message), which is fine: they end the replay of that frame.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/expected.h"
#include "core/image.h"

namespace mocap::formats_detail {

// The header is read (or looked at) in its first kPgmHeaderBufferBytes.
inline constexpr std::size_t kPgmHeaderBufferBytes = 4096;

struct PgmHeader {
  int width = 0;
  int height = 0;
  std::uint16_t maxval = 0;
  std::size_t header_bytes = 0;  // the pixels start here
};

// Parses the header in head[0..n); more_follows: the file goes on past n (a header
// that does not end within n is "longer than" the buffer, not truncated). Checks the
// size against expected_width/height when they are > 0. Errors name `path`.
Expected<PgmHeader> parse_pgm_header(const char* path, const std::uint8_t* head, std::size_t n,
                                     bool more_follows, int expected_width, int expected_height);

// expected_width/height <= 0: any size. When missing_ok is non-null and the file does
// not exist (ENOENT), sets *missing_ok = true and returns success without touching out.
Expected<void> read_pgm_path(const char* path, int expected_width, int expected_height, Image& out,
                             bool* missing_ok);

}  // namespace mocap::formats_detail
