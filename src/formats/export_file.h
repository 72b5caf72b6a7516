// Design: the output file of a streaming export (C3D, TRC): opened at setup with a
// one-line error naming the file, written with noexcept calls that remember the first
// failure (errno) instead of reporting it per frame, and closed with one error naming the
// file when anything failed (full disk, I/O error) — so a writer never loses the reason
// and the caller decides when to stop.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "core/expected.h"

namespace mocap::formats_detail {

class ExportFile {
 public:
  static Expected<ExportFile> open(const std::string& path);
  ExportFile(ExportFile&&) noexcept = default;
  ExportFile& operator=(ExportFile&&) noexcept = default;
  ~ExportFile() = default;

  // Appends n bytes; false (and nothing more is written) after any failure.
  bool write(const void* data, std::size_t n) noexcept;
  // Marks the file failed with `error` (e.g. EOVERFLOW for a line that does not fit).
  void fail(int error) noexcept;
  bool failed() const noexcept { return failed_; }
  std::uint64_t bytes_written() const noexcept { return bytes_; }
  const std::string& path() const noexcept { return path_; }
  // Flushes and closes: "<path>: cannot write: <reason>" when a write, the flush or the
  // close failed. A second call does nothing.
  Expected<void> close();

 private:
  ExportFile() = default;
  struct Closer {
    void operator()(std::FILE* f) const noexcept {
      if (f) std::fclose(f);
    }
  };
  std::unique_ptr<std::FILE, Closer> file_;
  std::string path_;
  std::uint64_t bytes_ = 0;
  int errno_ = 0;  // of the first failure
  bool failed_ = false;
};

}  // namespace mocap::formats_detail
