// Design: see pgm_map.h. The header is parsed by the reader's parse_pgm_header over the
// file's first kPgmHeaderBufferBytes, so both paths accept and reject the same files.
#include "formats/pgm_map.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include "formats/pgm_read.h"

namespace mocap {

MappedPgm::MappedPgm(MappedPgm&& o) noexcept
    : base_(std::exchange(o.base_, nullptr)),
      length_(std::exchange(o.length_, 0)),
      view_(std::exchange(o.view_, ImageView{})) {}

MappedPgm& MappedPgm::operator=(MappedPgm&& o) noexcept {
  if (this != &o) {
    reset();
    base_ = std::exchange(o.base_, nullptr);
    length_ = std::exchange(o.length_, 0);
    view_ = std::exchange(o.view_, ImageView{});
  }
  return *this;
}

void MappedPgm::reset() noexcept {
  if (base_ != nullptr) ::munmap(base_, length_);
  base_ = nullptr;
  length_ = 0;
  view_ = ImageView{};
}

Expected<PgmMapResult> map_pgm_path(const char* path, int expected_width, int expected_height,
                                    MappedPgm& out) {
  out.reset();
  // O_NONBLOCK: a FIFO in place of a frame file fails instead of blocking the replay.
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int e = errno;
    if (e == ENOENT) return PgmMapResult::kMissing;
    return make_error(path, "cannot open", std::strerror(e));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    return make_error(path, "cannot open", std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return make_error(path, "cannot open", "not a regular file");
  }
  const auto file_bytes = static_cast<std::size_t>(st.st_size);
  if (file_bytes == 0) {
    ::close(fd);
    return make_error(path, "", "empty file (expected a binary PGM, magic P5)");
  }
  void* base = ::mmap(nullptr, file_bytes, PROT_READ, MAP_PRIVATE, fd, 0);
  const int map_errno = errno;
  ::close(fd);  // the mapping keeps the file
  if (base == MAP_FAILED) return make_error(path, "cannot map", std::strerror(map_errno));
  MappedPgm m;
  m.base_ = base;
  m.length_ = file_bytes;
  const auto* bytes = static_cast<const std::uint8_t*>(base);
  const std::size_t head_n = std::min(file_bytes, formats_detail::kPgmHeaderBufferBytes);
  auto header = formats_detail::parse_pgm_header(path, bytes, head_n, file_bytes > head_n,
                                                 expected_width, expected_height);
  if (!header) return header.error();
  const auto width = static_cast<std::size_t>(header->width);
  const auto height = static_cast<std::size_t>(header->height);
  if (header->maxval > 255) return PgmMapResult::kNeedsCopy;  // m unmaps
  const std::size_t avail =
      file_bytes > header->header_bytes ? file_bytes - header->header_bytes : 0;
  if (avail < width * height) {
    return make_error(path, "",
                      "truncated pixel data: expected " + std::to_string(width * height) +
                          " bytes, got " + std::to_string(avail));
  }
  m.view_.data = bytes + header->header_bytes;
  m.view_.width = header->width;
  m.view_.height = header->height;
  m.view_.stride_bytes = header->width;
  m.view_.format = PixelFormat::kMono8;
  m.view_.maxval = header->maxval;
  out = std::move(m);
  return PgmMapResult::kMapped;
}

}  // namespace mocap
