// Design: an 8-bit binary PGM (P5, maxval <= 255) mapped read-only into memory: the
// zero-copy frame of a replay. map_pgm_path() opens the file, checks its header exactly
// as the reader does (pgm_read.h: the same one-line errors naming the file), maps it
// (mmap, PROT_READ, MAP_PRIVATE) and closes the descriptor; the pixels are then read
// straight from the page cache by whoever looks at view(), with no copy. A 16-bit file
// cannot be viewed in place (big-endian on disk), so it is reported as kNeedsCopy and
// the caller reads it (read_pgm). MappedPgm owns the mapping (move-only, munmap on
// reset() or destruction). No heap allocation on success; errors allocate their message.
#pragma once

#include <cstddef>

#include "core/expected.h"
#include "core/image.h"

namespace mocap {

enum class PgmMapResult { kMapped, kMissing, kNeedsCopy };

class MappedPgm {
 public:
  MappedPgm() = default;
  ~MappedPgm() { reset(); }
  MappedPgm(MappedPgm&& o) noexcept;
  MappedPgm& operator=(MappedPgm&& o) noexcept;
  MappedPgm(const MappedPgm&) = delete;
  MappedPgm& operator=(const MappedPgm&) = delete;

  bool mapped() const noexcept { return base_ != nullptr; }
  ImageView view() const noexcept { return view_; }
  void reset() noexcept;  // unmaps (nothing when not mapped)

 private:
  friend Expected<PgmMapResult> map_pgm_path(const char* path, int expected_width,
                                             int expected_height, MappedPgm& out);
  void* base_ = nullptr;
  std::size_t length_ = 0;
  ImageView view_{};
};

// Maps `path` into `out` (replacing what it held). kMissing: no such file (out empty);
// kNeedsCopy: a valid 16-bit PGM (out empty); an Error naming the file when it cannot be
// opened or is malformed, truncated or of another size than expected (> 0: checked).
Expected<PgmMapResult> map_pgm_path(const char* path, int expected_width, int expected_height,
                                    MappedPgm& out);

}  // namespace mocap
