// Design: see png_writer.h.
#include "formats/png_writer.h"

#include <zlib.h>

#include <cstdio>
#include <cstring>

namespace mocap {
namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data,
           std::size_t size) {
  put_u32(out, static_cast<std::uint32_t>(size));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  if (size > 0) out.insert(out.end(), data, data + size);
  const uLong crc = crc32(0L, out.data() + start, static_cast<uInt>(size + 4));
  put_u32(out, static_cast<std::uint32_t>(crc));
}

}  // namespace

Expected<std::vector<std::uint8_t>> encode_png(const RgbImage& img) {
  if (img.width < 1 || img.height < 1 ||
      img.rgb.size() !=
          static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 3)
    return make_error("png", "size", "empty or inconsistent image");
  const std::size_t row = static_cast<std::size_t>(img.width) * 3;
  std::vector<std::uint8_t> raw;
  raw.reserve((row + 1) * static_cast<std::size_t>(img.height));
  for (int y = 0; y < img.height; ++y) {
    raw.push_back(0);  // filter: none
    const auto* p = img.rgb.data() + static_cast<std::size_t>(y) * row;
    raw.insert(raw.end(), p, p + row);
  }
  uLongf zsize = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> z(zsize);
  if (compress(z.data(), &zsize, raw.data(), static_cast<uLong>(raw.size())) != Z_OK)
    return make_error("png", "zlib", "compress failed");
  std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  put_u32(ihdr, static_cast<std::uint32_t>(img.width));
  put_u32(ihdr, static_cast<std::uint32_t>(img.height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, filter 0, no interlace
  chunk(out, "IHDR", ihdr.data(), ihdr.size());
  chunk(out, "IDAT", z.data(), zsize);
  chunk(out, "IEND", nullptr, 0);
  return out;
}

Expected<void> write_png(const std::string& path, const RgbImage& image) {
  auto bytes = encode_png(image);
  if (!bytes) return bytes.error();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return make_error(path, "", std::string("cannot write: ") + std::strerror(errno));
  const bool ok = std::fwrite(bytes->data(), 1, bytes->size(), f) == bytes->size();
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) return make_error(path, "", "cannot write: disk full or I/O error");
  return {};
}

}  // namespace mocap
