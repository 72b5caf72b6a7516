// Design: the allocation-free core of the PGM reader (internal to mocap_formats), taking
// a C path so that callers such as Recording::load_frame can build the path in a stack
// buffer. On success with an Image of the right size and format it performs no heap
// allocation: open/fstat/read straight into the Image's buffer. Errors allocate (they
// build the message), which is fine: they end the replay of that frame.
#pragma once

#include "core/expected.h"
#include "core/image.h"

namespace mocap::formats_detail {

// expected_width/height <= 0: any size. When missing_ok is non-null and the file does
// not exist (ENOENT), sets *missing_ok = true and returns success without touching out.
Expected<void> read_pgm_path(const char* path, int expected_width, int expected_height, Image& out,
                             bool* missing_ok);

}  // namespace mocap::formats_detail
