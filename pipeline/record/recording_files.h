// Design: the files of a recording folder as `mocap record` writes them, so that what is
// on disk is a valid recording at every instant (a crash, a full disk or a stop signal
// leave a folder that `mocap track` reads):
//   - each PGM is written to "<name>.pgm.tmp" and renamed when complete, so a frame file
//     is either absent or whole;
//   - a frame's row is appended to frames.csv only after all its files were renamed; a
//     row that cannot be written completely is cut off again (ftruncate to the last good
//     length) and the frame's files are removed, so frames.csv and the files agree;
//   - finish() fsyncs frames.csv and syncfs()es the folder once (durability at the end,
//     without one fsync per file); blob recordings also fdatasync frames.csv about once a
//     second (set_sync_interval), as their blob files are.
// Writing is done by the recorder's writer thread (not real-time): plain POSIX I/O with
// one scratch buffer allocated at open. A test hook (byte_budget) turns the writes past
// a budget into ENOSPC, to test the full-disk path without a full disk.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/image.h"

namespace mocap::record {

class RecordingFiles {
 public:
  // Opens DIR/frames.csv (must not exist; writes the header) and creates one folder per
  // camera (camera_folders false: none, a blob recording that keeps no images).
  // `max_image_bytes`: the largest image (sizes the 16-bit scratch buffer).
  static Expected<RecordingFiles> open(const std::string& dir,
                                       const std::vector<std::string>& camera_names,
                                       std::size_t max_image_bytes, std::uint64_t byte_budget = 0,
                                       bool camera_folders = true);
  RecordingFiles(RecordingFiles&& other) noexcept;
  RecordingFiles& operator=(RecordingFiles&&) = delete;
  RecordingFiles(const RecordingFiles&) = delete;
  ~RecordingFiles();

  // Writes camera `camera`'s image of frame `frame` as a complete PGM file.
  Expected<void> write_image(int camera, std::int64_t frame, const ImageView& image);
  // Appends "frame,timestamp_ns" (frame after every file of it was written). On failure
  // the partial row is removed again.
  Expected<void> append_row(std::int64_t frame, std::int64_t timestamp_ns);
  // fdatasync frames.csv after a row at most every `ns` (< 0: only in finish(), the default).
  void set_sync_interval(std::int64_t ns) noexcept { sync_interval_ns_ = ns; }
  // Removes camera `camera`'s file of `frame` (a frame whose row could not be written).
  void remove_image(int camera, std::int64_t frame) noexcept;
  // fsync(frames.csv), syncfs(folder), close.
  Expected<void> finish();

  std::uint64_t bytes_written() const noexcept { return bytes_written_; }
  const std::string& dir() const noexcept { return dir_; }

 private:
  RecordingFiles() = default;
  // write() all of `n` bytes, honouring the byte budget; false with errno set.
  bool write_all(int fd, const std::uint8_t* data, std::size_t n) noexcept;

  std::string dir_;
  std::vector<std::string> cameras_;
  int csv_fd_ = -1;
  std::uint64_t csv_length_ = 0;  // bytes of complete rows
  std::uint64_t bytes_written_ = 0;
  std::uint64_t byte_budget_ = 0;  // 0: unlimited
  std::int64_t sync_interval_ns_ = -1;
  std::int64_t last_sync_ns_ = 0;
  std::vector<std::uint8_t> scratch_;
};

}  // namespace mocap::record
