// Design: binary PGM (P5) reader/writer (see pgm.h, pgm_read.h, docs/formats.md).
// The header (magic, width, height, maxval, '#' comments anywhere between tokens) is
// read into a stack buffer with one read(); the pixel bytes that followed it in that
// buffer are copied and the rest is read straight into the Image. 16-bit samples are
// big-endian on disk and swapped in place on little-endian hosts.
#include "formats/pgm.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "formats/pgm_read.h"

namespace mocap {
namespace formats_detail {
namespace {

constexpr std::size_t kHeaderBufferBytes = 4096;

class Fd {
 public:
  explicit Fd(int fd) noexcept : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const noexcept { return fd_; }

 private:
  int fd_;
};

// Reads up to n bytes (fewer only at end of file). Returns the count, or -1 on error.
long read_fully(int fd, std::uint8_t* dst, std::size_t n) noexcept {
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::read(fd, dst + got, n - got);
    if (r < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (r == 0) break;
    got += static_cast<std::size_t>(r);
  }
  return static_cast<long>(got);
}

bool is_space(std::uint8_t c) noexcept {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// Header tokenizer over the bytes read so far.
struct HeaderCursor {
  const std::uint8_t* p;
  std::size_t n;
  std::size_t pos = 0;

  void skip_space_and_comments() noexcept {
    while (pos < n) {
      if (is_space(p[pos])) {
        ++pos;
      } else if (p[pos] == '#') {
        while (pos < n && p[pos] != '\n' && p[pos] != '\r') ++pos;
      } else {
        break;
      }
    }
  }
  // 0: ok; 1: end of data; 2: not a number; 3: too large.
  int number(long& value) noexcept {
    skip_space_and_comments();
    if (pos >= n) return 1;
    if (p[pos] < '0' || p[pos] > '9') return 2;
    long v = 0;
    while (pos < n && p[pos] >= '0' && p[pos] <= '9') {
      v = v * 10 + (p[pos] - '0');
      if (v > 1000000000L) return 3;
      ++pos;
    }
    value = v;
    return 0;
  }
};

Error header_error(const char* path, const std::string& what) { return make_error(path, "", what); }

}  // namespace

Expected<void> read_pgm_path(const char* path, int expected_width, int expected_height, Image& out,
                             bool* missing_ok) {
  // O_NONBLOCK: a FIFO or device in place of a frame file must fail, never block the
  // replay (no effect on regular files).
  Fd fd(::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK));
  if (fd.get() < 0) {
    const int e = errno;
    if (missing_ok != nullptr && e == ENOENT) {
      *missing_ok = true;
      return {};
    }
    return make_error(path, "cannot open", std::strerror(e));
  }
  if (missing_ok != nullptr) *missing_ok = false;
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return make_error(path, "cannot open", std::strerror(errno));
  if (S_ISDIR(st.st_mode)) return make_error(path, "cannot open", "is a directory");

  std::uint8_t head[kHeaderBufferBytes];
  const long n_read = read_fully(fd.get(), head, sizeof head);
  if (n_read < 0) return make_error(path, "cannot read", std::strerror(errno));
  const auto n = static_cast<std::size_t>(n_read);
  if (n == 0) return header_error(path, "empty file (expected a binary PGM, magic P5)");
  if (n < 2 || head[0] != 'P' || head[1] != '5') {
    if (n >= 2 && head[0] == 'P' && head[1] >= '0' && head[1] <= '9') {
      return header_error(path, std::string("unsupported PGM/PNM magic 'P") +
                                    static_cast<char>(head[1]) + "' (expected binary PGM 'P5')");
    }
    return header_error(path, "not a PGM file (expected magic 'P5')");
  }
  HeaderCursor cur{head, n, 2};
  if (cur.pos < n && !is_space(head[cur.pos]) && head[cur.pos] != '#') {
    return header_error(path, "not a PGM file (expected whitespace after magic 'P5')");
  }
  long fields[3] = {0, 0, 0};
  static constexpr const char* kNames[3] = {"width", "height", "maxval"};
  for (int i = 0; i < 3; ++i) {
    const int r = cur.number(fields[i]);
    if (r == 1) {
      if (n == sizeof head) {
        return header_error(path, std::string("header longer than ") +
                                      std::to_string(kHeaderBufferBytes) + " bytes (at " +
                                      kNames[i] + ")");
      }
      return header_error(path, std::string("truncated header (no ") + kNames[i] + ")");
    }
    if (r == 2)
      return header_error(path, std::string("bad header: ") + kNames[i] + " is not a number");
    if (r == 3)
      return header_error(path, std::string("bad header: ") + kNames[i] + " is too large");
  }
  const long width = fields[0];
  const long height = fields[1];
  const long maxval = fields[2];
  if (width < 1 || width > kMaxImageSidePx || height < 1 || height > kMaxImageSidePx) {
    return header_error(path, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                  " out of range (1.." + std::to_string(kMaxImageSidePx) +
                                  " per side)");
  }
  if (maxval < 1 || maxval > 65535) {
    return header_error(path, "maxval " + std::to_string(maxval) + " out of range 1..65535");
  }
  // Exactly one whitespace byte separates maxval from the pixels.
  if (cur.pos < n && !is_space(head[cur.pos])) {
    return header_error(path, "bad header: maxval is not followed by whitespace");
  }
  const std::size_t header_bytes = cur.pos + 1;
  if (expected_width > 0 && (width != expected_width || height != expected_height)) {
    return header_error(path, "size " + std::to_string(width) + "x" + std::to_string(height) +
                                  " differs from the rig's " + std::to_string(expected_width) +
                                  "x" + std::to_string(expected_height));
  }
  const PixelFormat format = maxval <= 255 ? PixelFormat::kMono8 : PixelFormat::kMono16;
  const std::size_t pixel_bytes = static_cast<std::size_t>(width) *
                                  static_cast<std::size_t>(height) *
                                  static_cast<std::size_t>(bytes_per_pixel(format));
  auto truncated = [&](std::size_t got) {
    return header_error(path, "truncated pixel data: expected " + std::to_string(pixel_bytes) +
                                  " bytes, got " + std::to_string(got));
  };
  if (S_ISREG(st.st_mode)) {
    const auto file_bytes = static_cast<std::size_t>(st.st_size);
    const std::size_t avail = file_bytes > header_bytes ? file_bytes - header_bytes : 0;
    if (avail < pixel_bytes) return truncated(avail);
  }
  if (out.width() != width || out.height() != height || out.format() != format) {
    out.allocate(static_cast<int>(width), static_cast<int>(height), format,
                 static_cast<std::uint16_t>(maxval));
  }
  out.set_maxval(static_cast<std::uint16_t>(maxval));
  std::uint8_t* dst = out.data();
  const std::size_t in_head = n > header_bytes ? std::min(n - header_bytes, pixel_bytes) : 0;
  if (in_head > 0) std::memcpy(dst, head + header_bytes, in_head);
  if (in_head < pixel_bytes) {
    const long got = read_fully(fd.get(), dst + in_head, pixel_bytes - in_head);
    if (got < 0) return make_error(path, "cannot read", std::strerror(errno));
    if (static_cast<std::size_t>(got) < pixel_bytes - in_head) {
      return truncated(in_head + static_cast<std::size_t>(got));
    }
  }
  if (format == PixelFormat::kMono16 && std::endian::native == std::endian::little) {
    // The Image's buffer is uint16-aligned (it is only ever accessed as uint16 rows).
    auto* px = reinterpret_cast<std::uint16_t*>(dst);
    const std::size_t count = pixel_bytes / 2;
    for (std::size_t i = 0; i < count; ++i) px[i] = __builtin_bswap16(px[i]);  // vectorises
  }
  return {};
}

}  // namespace formats_detail

Expected<void> read_pgm(const std::string& path, Image& out) {
  return formats_detail::read_pgm_path(path.c_str(), 0, 0, out, nullptr);
}

Expected<void> read_pgm_expect(const std::string& path, int expected_width, int expected_height,
                               Image& out) {
  return formats_detail::read_pgm_path(path.c_str(), expected_width, expected_height, out, nullptr);
}

Expected<void> write_pgm(const std::string& path, const ImageView& image) {
  if (image.empty()) return make_error(path, "", "cannot write an empty image");
  if (image.width > kMaxImageSidePx || image.height > kMaxImageSidePx) {
    return make_error(path, "",
                      "image too large to write (" + std::to_string(image.width) + "x" +
                          std::to_string(image.height) + ")");
  }
  const bool wide = image.format == PixelFormat::kMono16;
  if (image.maxval == 0 || (!wide && image.maxval > 255) || (wide && image.maxval < 256)) {
    return make_error(path, "",
                      "maxval " + std::to_string(image.maxval) + " does not fit a " +
                          (wide ? "16-bit image (256..65535)" : "8-bit image (1..255)"));
  }
  struct Closer {
    void operator()(std::FILE* f) const noexcept {
      if (f) std::fclose(f);
    }
  };
  errno = 0;
  std::unique_ptr<std::FILE, Closer> f(std::fopen(path.c_str(), "wb"));
  if (!f) return make_error(path, "cannot write", std::strerror(errno));
  bool ok = std::fprintf(f.get(), "P5\n%d %d\n%d\n", image.width, image.height,
                         static_cast<int>(image.maxval)) > 0;
  const auto row_bytes = static_cast<std::size_t>(image.width) * (wide ? 2u : 1u);
  std::vector<std::uint8_t> row(wide ? row_bytes : 0);
  for (int y = 0; y < image.height && ok; ++y) {
    const std::uint8_t* src = image.row8(y);
    if (wide) {
      const std::uint16_t* s16 = image.row16(y);
      for (int x = 0; x < image.width; ++x) {
        row[2 * static_cast<std::size_t>(x)] = static_cast<std::uint8_t>(s16[x] >> 8);
        row[2 * static_cast<std::size_t>(x) + 1] = static_cast<std::uint8_t>(s16[x] & 0xFF);
      }
      src = row.data();
    }
    ok = std::fwrite(src, 1, row_bytes, f.get()) == row_bytes;
  }
  std::FILE* raw = f.release();
  const int close_rc = std::fclose(raw);
  if (!ok || close_rc != 0) return make_error(path, "cannot write", std::strerror(errno));
  return {};
}

}  // namespace mocap
