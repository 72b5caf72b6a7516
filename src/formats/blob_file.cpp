// Design: see blob_file.h. Byte layout (all little-endian; docs/formats.md, "Blob recordings"):
//   header  0 magic "MOCAPBLB" | 8 u16 version | 10 u16 header_bytes (= 36 + n) |
//           12 u16 record_bytes | 14 u16 n (camera name bytes, 1..255) | 16 u32 width |
//           20 u32 height | 24 u32 max_blobs | 28 u32 reserved (0) | 32 name |
//           32+n u32 CRC-32 of bytes [0, 32+n)
//   chunk   0 "BLBF" | 4 u32 count | 8 i64 frame | 16 i64 timestamp_ns | 24 f64 background_dn
//           | 32 f64 noise_dn | 40 f64 threshold_dn | 48 count records | u32 CRC-32 of all before
//   record  0 f64 x_px | 8 f64 y_px | 16 f32 area_px | 20 f32 sum_dn | 24 u16 peak_dn |
//           26 u16 background_dn | 28 u16 x_min, y_min, x_max, y_max | 36 f32 major_axis_px,
//           minor_axis_px, roundness, eccentricity, orientation_rad | 56 u32 flags
// A reader of version 1 takes the first 60 bytes of each record and skips the rest
// (record_bytes > 60: fields a later writer appended within version 1).
#include "formats/blob_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>

#include "formats/blob_file_codec.h"

namespace mocap {

using namespace blob_codec;

void encode_blob_record(const detect::Blob& b, std::uint8_t* p) noexcept {
  putd(p + 0, b.x_px);
  putd(p + 8, b.y_px);
  putf(p + 16, b.area_px);
  putf(p + 20, b.sum_dn);
  put16(p + 24, b.peak_dn);
  put16(p + 26, b.background_dn);
  put16(p + 28, box16(b.x_min));
  put16(p + 30, box16(b.y_min));
  put16(p + 32, box16(b.x_max));
  put16(p + 34, box16(b.y_max));
  putf(p + 36, b.major_axis_px);
  putf(p + 40, b.minor_axis_px);
  putf(p + 44, b.roundness);
  putf(p + 48, b.eccentricity);
  putf(p + 52, b.orientation_rad);
  put32(p + 56, b.flags);
}

detect::Blob decode_blob_record(const std::uint8_t* p) noexcept {
  detect::Blob b;
  b.x_px = getd(p + 0);
  b.y_px = getd(p + 8);
  b.area_px = getf(p + 16);
  b.sum_dn = getf(p + 20);
  b.peak_dn = get16(p + 24);
  b.background_dn = get16(p + 26);
  b.x_min = get16(p + 28);
  b.y_min = get16(p + 30);
  b.x_max = get16(p + 32);
  b.y_max = get16(p + 34);
  b.major_axis_px = getf(p + 36);
  b.minor_axis_px = getf(p + 40);
  b.roundness = getf(p + 44);
  b.eccentricity = getf(p + 48);
  b.orientation_rad = getf(p + 52);
  b.flags = get32(p + 56);
  return b;
}

namespace {

// Whether a whole, CRC-valid chunk starts at `off`; fills `c`. `buf` is reused.
bool chunk_at(int fd, std::uint64_t size, std::uint64_t off, const BlobFileInfo& info,
              std::vector<std::uint8_t>& buf, BlobFileReader::Chunk& c) {
  if (size < off || size - off < kBlobChunkHeaderBytes + 4) return false;
  std::uint8_t h[kBlobChunkHeaderBytes];
  if (!read_at(fd, h, sizeof h, off) || std::memcmp(h, kSync, 4) != 0) return false;
  const std::uint32_t count = get32(h + 4);
  if (count > info.max_blobs) return false;
  const std::uint64_t len =
      kBlobChunkHeaderBytes + static_cast<std::uint64_t>(count) * info.record_bytes + 4;
  if (size - off < len) return false;
  buf.resize(static_cast<std::size_t>(len));
  if (!read_at(fd, buf.data(), buf.size(), off)) return false;
  if (get32(buf.data() + len - 4) != crc(buf.data(), static_cast<std::size_t>(len - 4)))
    return false;
  c.offset = off;
  c.count = count;
  c.frame = static_cast<std::int64_t>(get64(h + 8));
  c.timestamp_ns = static_cast<std::int64_t>(get64(h + 16));
  return true;
}

// The next offset >= from where a valid chunk starts, or `size` if none.
std::uint64_t next_chunk(int fd, std::uint64_t size, std::uint64_t from, const BlobFileInfo& info,
                         std::vector<std::uint8_t>& buf) {
  std::vector<std::uint8_t> block(1 << 16);
  BlobFileReader::Chunk c;
  while (from + 4 <= size) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(block.size(), size - from));
    if (!read_at(fd, block.data(), n, from)) return size;
    for (std::size_t i = 0; i + 4 <= n; ++i) {
      if (std::memcmp(&block[i], kSync, 4) == 0 && chunk_at(fd, size, from + i, info, buf, c))
        return from + i;
    }
    if (n < 4) break;
    from += n - 3;  // a sync word across the block boundary is found in the next block
  }
  return size;
}

}  // namespace

Expected<BlobFileReader> BlobFileReader::open(const std::string& path,
                                              std::vector<std::string>& warnings) {
  BlobFileReader r;
  r.path_ = path;
  r.fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (r.fd_ < 0) return make_error(path, "", std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(r.fd_, &st) != 0 || !S_ISREG(st.st_mode))
    return make_error(path, "", "not a regular file");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  std::uint8_t h[kFixedHeaderBytes];
  if (size < kFixedHeaderBytes + 5 || !read_at(r.fd_, h, sizeof h, 0))
    return make_error(path, "", "not a blob file (shorter than its header)");
  if (std::memcmp(h, kMagic, 8) != 0)
    return make_error(path, "", "not a blob file (no \"MOCAPBLB\" magic at byte 0)");
  BlobFileInfo& info = r.info_;
  info.version = get16(h + 8);
  if (info.version != kBlobFileVersion)
    return make_error(path, "",
                      "blob file version " + std::to_string(info.version) +
                          ", this mocap reads version " + std::to_string(kBlobFileVersion));
  const std::uint16_t header_bytes = get16(h + 10);
  info.record_bytes = get16(h + 12);
  const std::uint16_t n = get16(h + 14);
  if (n < 1 || n > 255 || header_bytes != kFixedHeaderBytes + n + 4 || header_bytes > size)
    return make_error(path, "header",
                      "inconsistent sizes (camera name " + std::to_string(n) + " bytes, header " +
                          std::to_string(header_bytes) + " bytes)");
  if (info.record_bytes < kBlobRecordBytes || info.record_bytes > kMaxRecordBytes)
    return make_error(path, "header",
                      "blob record of " + std::to_string(info.record_bytes) + " bytes, expected " +
                          std::to_string(kBlobRecordBytes) + ".." +
                          std::to_string(kMaxRecordBytes));
  std::vector<std::uint8_t> hdr(header_bytes);
  if (!read_at(r.fd_, hdr.data(), hdr.size(), 0))
    return make_error(path, "", "cannot read the header");
  if (get32(&hdr[header_bytes - 4u]) != crc(hdr.data(), header_bytes - 4u))
    return make_error(path, "header", "CRC mismatch (the header is damaged)");
  info.width = static_cast<int>(std::min<std::uint32_t>(get32(h + 16), 1u << 30));
  info.height = static_cast<int>(std::min<std::uint32_t>(get32(h + 20), 1u << 30));
  info.max_blobs = get32(h + 24);
  if (info.max_blobs < 1 || info.max_blobs > kMaxBlobFileBlobs)
    return make_error(path, "header",
                      "blob capacity " + std::to_string(info.max_blobs) + " outside 1.." +
                          std::to_string(kMaxBlobFileBlobs));
  info.camera.assign(reinterpret_cast<const char*>(&hdr[kFixedHeaderBytes]), n);
  r.data_start_ = header_bytes;

  std::vector<std::uint8_t> buf;
  std::uint64_t off = header_bytes;
  Chunk c;
  while (off < size) {
    if (chunk_at(r.fd_, size, off, info, buf, c)) {
      if (r.chunks_.empty() || c.frame > r.chunks_.back().frame) {
        r.chunks_.push_back(c);
      } else {
        warnings.push_back(path + ": chunk at " + offset_text(off) + ": frame " +
                           std::to_string(c.frame) + " does not follow frame " +
                           std::to_string(r.chunks_.back().frame) + ", skipped");
        ++r.damaged_regions_;
      }
      off += kBlobChunkHeaderBytes + std::uint64_t{c.count} * info.record_bytes + 4;
      continue;
    }
    const std::uint64_t next = next_chunk(r.fd_, size, off + 1, info, buf);
    if (next >= size) {
      r.torn_bytes_ = size - off;
      warnings.push_back(path + ": torn tail at " + offset_text(off) + " (" +
                         std::to_string(size - off) +
                         " bytes after the last whole frame ignored: the writer stopped there)");
      break;
    }
    warnings.push_back(path + ": damaged bytes at " + offset_text(off) + ".." +
                       std::to_string(next) +
                       " (no whole chunk with a valid CRC) skipped; the "
                       "frames in them read as dropped");
    r.damaged_bytes_ += next - off;
    ++r.damaged_regions_;
    off = next;
  }
  return r;
}

BlobFileReader::BlobFileReader(BlobFileReader&& o) noexcept
    : path_(std::move(o.path_)),
      fd_(o.fd_),
      info_(std::move(o.info_)),
      data_start_(o.data_start_),
      chunks_(std::move(o.chunks_)),
      damaged_bytes_(o.damaged_bytes_),
      torn_bytes_(o.torn_bytes_),
      damaged_regions_(o.damaged_regions_) {
  o.fd_ = -1;
}

BlobFileReader::~BlobFileReader() {
  if (fd_ >= 0) ::close(fd_);
}

const BlobFileReader::Chunk* BlobFileReader::find(std::int64_t frame) const noexcept {
  auto it = std::lower_bound(chunks_.begin(), chunks_.end(), frame,
                             [](const Chunk& c, std::int64_t f) { return c.frame < f; });
  return it != chunks_.end() && it->frame == frame ? &*it : nullptr;
}

Expected<void> BlobFileReader::load(const Chunk& chunk, detect::BlobList& out,
                                    std::vector<std::uint8_t>& scratch) const {
  out.clear();
  const std::size_t len = kBlobChunkHeaderBytes + std::size_t{chunk.count} * info_.record_bytes + 4;
  if (scratch.size() < len) scratch.resize(len);
  const std::uint8_t* p = scratch.data();
  if (!read_at(fd_, scratch.data(), len, chunk.offset) || std::memcmp(p, kSync, 4) != 0 ||
      get32(p + 4) != chunk.count || get32(p + len - 4) != crc(p, len - 4))
    return make_error(path_, "",
                      "chunk of frame " + std::to_string(chunk.frame) + " at " +
                          offset_text(chunk.offset) + " changed since the recording was opened");
  out.set_levels({getd(p + 24), getd(p + 32), getd(p + 40)});
  for (std::uint32_t i = 0; i < chunk.count; ++i)
    out.push_back(
        decode_blob_record(p + kBlobChunkHeaderBytes + i * std::size_t{info_.record_bytes}));
  return {};
}

}  // namespace mocap
