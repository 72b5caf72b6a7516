// Design: see recording_files.h.
#include "pipeline/record/recording_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "core/clock.h"
#include "formats/recording.h"

namespace mocap::record {

namespace {

Error io_error(const std::string& path, const char* what, int err) {
  return make_error(path, what, std::strerror(err));
}

}  // namespace

Expected<RecordingFiles> RecordingFiles::open(const std::string& dir,
                                              const std::vector<std::string>& camera_names,
                                              std::size_t max_image_bytes,
                                              std::uint64_t byte_budget, bool camera_folders) {
  RecordingFiles f;
  f.dir_ = dir;
  f.cameras_ = camera_names;
  f.byte_budget_ = byte_budget;
  f.scratch_.resize(max_image_bytes + 64);
  for (const std::string& cam : camera_names) {
    if (!camera_folders) break;
    const std::string sub = dir + "/" + cam;
    if (::mkdir(sub.c_str(), 0755) != 0 && errno != EEXIST)
      return io_error(sub, "cannot create the camera folder", errno);
  }
  const std::string csv = dir + "/frames.csv";
  f.csv_fd_ = ::open(csv.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (f.csv_fd_ < 0) return io_error(csv, "cannot create", errno);
  static constexpr char kHeader[] = "frame,timestamp_ns\n";
  if (!f.write_all(f.csv_fd_, reinterpret_cast<const std::uint8_t*>(kHeader), sizeof kHeader - 1)) {
    return io_error(csv, "cannot write", errno);
  }
  f.csv_length_ = sizeof kHeader - 1;
  return f;
}

RecordingFiles::RecordingFiles(RecordingFiles&& o) noexcept
    : dir_(std::move(o.dir_)),
      cameras_(std::move(o.cameras_)),
      csv_fd_(std::exchange(o.csv_fd_, -1)),
      csv_length_(o.csv_length_),
      bytes_written_(o.bytes_written_),
      byte_budget_(o.byte_budget_),
      sync_interval_ns_(o.sync_interval_ns_),
      last_sync_ns_(o.last_sync_ns_),
      scratch_(std::move(o.scratch_)) {}

RecordingFiles::~RecordingFiles() {
  if (csv_fd_ >= 0) ::close(csv_fd_);
}

bool RecordingFiles::write_all(int fd, const std::uint8_t* data, std::size_t n) noexcept {
  while (n > 0) {
    std::size_t chunk = n;
    if (byte_budget_ != 0) {  // test hook: the disk is full past the budget
      if (bytes_written_ >= byte_budget_) {
        errno = ENOSPC;
        return false;
      }
      chunk =
          static_cast<std::size_t>(std::min<std::uint64_t>(chunk, byte_budget_ - bytes_written_));
    }
    const ssize_t w = ::write(fd, data, chunk);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (w == 0) {
      errno = ENOSPC;
      return false;
    }
    data += w;
    n -= static_cast<std::size_t>(w);
    bytes_written_ += static_cast<std::uint64_t>(w);
  }
  return true;
}

Expected<void> RecordingFiles::write_image(int camera, std::int64_t frame, const ImageView& image) {
  const std::string path = frame_file_path(dir_, cameras_[static_cast<std::size_t>(camera)], frame);
  const std::string tmp = path + ".tmp";
  const bool wide = image.format == PixelFormat::kMono16;
  char header[64];
  const int header_len = std::snprintf(header, sizeof header, "P5\n%d %d\n%d\n", image.width,
                                       image.height, static_cast<int>(image.maxval));
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * (wide ? 2u : 1u);
  const std::size_t data_bytes = row_bytes * static_cast<std::size_t>(image.height);
  if (header_len <= 0 || data_bytes > scratch_.size())
    return make_error(path, "", "image larger than the recorder's slots");
  // 8-bit rows packed in memory are written straight from the image (no copy); 16-bit
  // pixels are swapped to big-endian into the scratch buffer.
  const std::uint8_t* pixels = image.data;
  if (wide || image.stride_bytes != static_cast<int>(row_bytes)) {
    std::uint8_t* px = scratch_.data();
    for (int y = 0; y < image.height; ++y) {
      std::uint8_t* dst = px + static_cast<std::size_t>(y) * row_bytes;
      if (!wide) {
        std::memcpy(dst, image.row8(y), row_bytes);
      } else {
        const std::uint16_t* s16 = image.row16(y);
        for (int x = 0; x < image.width; ++x) {
          dst[2 * static_cast<std::size_t>(x)] = static_cast<std::uint8_t>(s16[x] >> 8);
          dst[2 * static_cast<std::size_t>(x) + 1] = static_cast<std::uint8_t>(s16[x] & 0xff);
        }
      }
    }
    pixels = px;
  }
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return io_error(path, "cannot write", errno);
  const bool ok = write_all(fd, reinterpret_cast<const std::uint8_t*>(header),
                            static_cast<std::size_t>(header_len)) &&
                  write_all(fd, pixels, data_bytes);
  const int err = errno;
  const bool closed = ::close(fd) == 0;
  if (!ok || !closed) {
    ::unlink(tmp.c_str());
    return io_error(path, "cannot write", ok ? errno : err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return io_error(path, "cannot rename", e);
  }
  return {};
}

Expected<void> RecordingFiles::append_row(std::int64_t frame, std::int64_t timestamp_ns) {
  char row[64];
  const int n = std::snprintf(row, sizeof row, "%lld,%lld\n", static_cast<long long>(frame),
                              static_cast<long long>(timestamp_ns));
  if (n <= 0) return make_error(dir_ + "/frames.csv", "", "cannot format a row");
  if (!write_all(csv_fd_, reinterpret_cast<const std::uint8_t*>(row),
                 static_cast<std::size_t>(n))) {
    const int err = errno;
    // Cut the partial row off again: frames.csv keeps only complete rows.
    if (::ftruncate(csv_fd_, static_cast<off_t>(csv_length_)) == 0)
      ::lseek(csv_fd_, static_cast<off_t>(csv_length_), SEEK_SET);
    return io_error(dir_ + "/frames.csv", "cannot write", err);
  }
  csv_length_ += static_cast<std::uint64_t>(n);
  if (sync_interval_ns_ >= 0) {  // blob recordings: bounded loss on power failure
    const std::int64_t now = monotonic_ns();
    if (now - last_sync_ns_ >= sync_interval_ns_) {
      last_sync_ns_ = now;
      (void)::fdatasync(csv_fd_);  // a failure shows again in finish()'s fsync
    }
  }
  return {};
}

void RecordingFiles::remove_image(int camera, std::int64_t frame) noexcept {
  const std::string path = frame_file_path(dir_, cameras_[static_cast<std::size_t>(camera)], frame);
  ::unlink(path.c_str());
}

Expected<void> RecordingFiles::finish() {
  if (csv_fd_ < 0) return {};
  const std::string csv = dir_ + "/frames.csv";
  Expected<void> result;
  if (::fsync(csv_fd_) != 0) result = io_error(csv, "cannot fsync", errno);
  // One syncfs for every file of the folder instead of one fsync per image.
  if (::syncfs(csv_fd_) != 0 && result) result = io_error(dir_, "cannot sync", errno);
  if (::close(csv_fd_) != 0 && result) result = io_error(csv, "cannot close", errno);
  csv_fd_ = -1;
  return result;
}

}  // namespace mocap::record
