// Design: the blob file's writer (see blob_file.h, the byte layout in blob_file.cpp).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "core/clock.h"
#include "formats/blob_file.h"
#include "formats/blob_file_codec.h"

namespace mocap {

using namespace blob_codec;

Expected<BlobFileWriter> BlobFileWriter::create(const std::string& path, const BlobFileInfo& info,
                                                std::int64_t sync_interval_ns,
                                                std::uint64_t byte_budget) {
  if (info.camera.empty() || info.camera.size() > 255)
    return make_error(path, "camera", "name must have 1..255 bytes");
  if (info.width < 1 || info.width > 65535 || info.height < 1 || info.height > 65535)
    return make_error(path, "", "image size must be 1..65535 pixels each way");
  if (info.max_blobs < 1 || info.max_blobs > kMaxBlobFileBlobs)
    return make_error(path, "max_blobs", "must be 1.." + std::to_string(kMaxBlobFileBlobs));
  BlobFileWriter w;
  w.path_ = path;
  w.max_blobs_ = info.max_blobs;
  w.sync_interval_ns_ = sync_interval_ns;
  w.byte_budget_ = byte_budget;
  w.chunk_.assign(kBlobChunkHeaderBytes + info.max_blobs * kBlobRecordBytes + 4, 0);
  w.fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (w.fd_ < 0) return make_error(path, "", std::string("cannot create: ") + std::strerror(errno));
  const std::size_t n = info.camera.size();
  std::vector<std::uint8_t> h(kFixedHeaderBytes + n + 4, 0);
  std::memcpy(h.data(), kMagic, 8);
  put16(&h[8], kBlobFileVersion);
  put16(&h[10], static_cast<std::uint16_t>(h.size()));
  put16(&h[12], static_cast<std::uint16_t>(kBlobRecordBytes));
  put16(&h[14], static_cast<std::uint16_t>(n));
  put32(&h[16], static_cast<std::uint32_t>(info.width));
  put32(&h[20], static_cast<std::uint32_t>(info.height));
  put32(&h[24], info.max_blobs);
  std::memcpy(&h[kFixedHeaderBytes], info.camera.data(), n);
  put32(&h[kFixedHeaderBytes + n], crc(h.data(), kFixedHeaderBytes + n));
  if (!w.write_all(h.data(), h.size()))
    return make_error(path, "", std::string("cannot write the header: ") + std::strerror(errno));
  w.length_ = h.size();
  w.last_sync_ns_ = monotonic_ns();
  return w;
}

BlobFileWriter::BlobFileWriter(BlobFileWriter&& o) noexcept { *this = std::move(o); }

BlobFileWriter& BlobFileWriter::operator=(BlobFileWriter&& o) noexcept {
  if (this == &o) return *this;
  if (fd_ >= 0) ::close(fd_);
  path_ = std::move(o.path_);
  fd_ = o.fd_;
  o.fd_ = -1;
  max_blobs_ = o.max_blobs_;
  length_ = o.length_;
  last_frame_ = o.last_frame_;
  sync_interval_ns_ = o.sync_interval_ns_;
  last_sync_ns_ = o.last_sync_ns_;
  byte_budget_ = o.byte_budget_;
  chunk_ = std::move(o.chunk_);
  return *this;
}

BlobFileWriter::~BlobFileWriter() {
  if (fd_ >= 0) ::close(fd_);
}

bool BlobFileWriter::write_all(const std::uint8_t* data, std::size_t n) noexcept {
  std::uint64_t off = length_;
  while (n > 0) {
    std::size_t step = n;
    if (byte_budget_ != 0) {
      if (off >= byte_budget_) {
        errno = ENOSPC;
        return false;
      }
      step = std::min<std::uint64_t>(step, byte_budget_ - off);
    }
    const ssize_t r = ::pwrite(fd_, data, step, static_cast<off_t>(off));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      if (r == 0) errno = ENOSPC;
      return false;
    }
    data += r;
    n -= static_cast<std::size_t>(r);
    off += static_cast<std::uint64_t>(r);
  }
  return true;
}

Expected<void> BlobFileWriter::append(std::int64_t frame, std::int64_t timestamp_ns,
                                      const detect::BlobList& blobs) {
  if (fd_ < 0) return make_error(path_, "", "closed");
  if (frame <= last_frame_)
    return make_error(
        path_, "",
        "frame " + std::to_string(frame) + " does not follow frame " + std::to_string(last_frame_));
  const std::size_t count = blobs.size();
  if (count > max_blobs_)
    return make_error(path_, "",
                      std::to_string(count) + " blobs, the file holds at most " +
                          std::to_string(max_blobs_) + " per frame");
  std::uint8_t* p = chunk_.data();
  std::memcpy(p, kSync, 4);
  put32(p + 4, static_cast<std::uint32_t>(count));
  put64(p + 8, static_cast<std::uint64_t>(frame));
  put64(p + 16, static_cast<std::uint64_t>(timestamp_ns));
  putd(p + 24, blobs.levels().background_dn);
  putd(p + 32, blobs.levels().noise_dn);
  putd(p + 40, blobs.levels().threshold_dn);
  for (std::size_t i = 0; i < count; ++i)
    encode_blob_record(blobs[i], p + kBlobChunkHeaderBytes + i * kBlobRecordBytes);
  const std::size_t body = kBlobChunkHeaderBytes + count * kBlobRecordBytes;
  put32(p + body, crc(p, body));
  if (!write_all(p, body + 4)) {
    const int e = errno;
    // The file ends on its last whole chunk again (what a reader would skip anyway).
    if (::ftruncate(fd_, static_cast<off_t>(length_)) != 0) {
    }
    return make_error(path_, "",
                      "cannot write frame " + std::to_string(frame) + ": " + std::strerror(e));
  }
  length_ += body + 4;
  last_frame_ = frame;
  if (sync_interval_ns_ >= 0) {
    const std::int64_t now = monotonic_ns();
    if (now - last_sync_ns_ >= sync_interval_ns_) {
      last_sync_ns_ = now;
      if (::fdatasync(fd_) != 0)
        return make_error(path_, "", std::string("fdatasync failed: ") + std::strerror(errno));
    }
  }
  return {};
}

Expected<void> BlobFileWriter::close() {
  if (fd_ < 0) return {};
  const bool synced = ::fdatasync(fd_) == 0;
  const int e = errno;
  ::close(fd_);
  fd_ = -1;
  if (!synced) return make_error(path_, "", std::string("fdatasync failed: ") + std::strerror(e));
  return {};
}

}  // namespace mocap
