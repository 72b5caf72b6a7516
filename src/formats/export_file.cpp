// Design: see export_file.h.
#include "formats/export_file.h"

#include <cerrno>
#include <cstring>

namespace mocap::formats_detail {

Expected<ExportFile> ExportFile::open(const std::string& path) {
  ExportFile f;
  f.path_ = path;
  errno = 0;
  f.file_.reset(std::fopen(path.c_str(), "wb"));
  if (!f.file_) return make_error(path, "cannot write", std::strerror(errno));
  return f;
}

bool ExportFile::write(const void* data, std::size_t n) noexcept {
  if (failed_ || !file_) return false;
  if (std::fwrite(data, 1, n, file_.get()) != n) {
    fail(errno);
    return false;
  }
  bytes_ += n;
  return true;
}

void ExportFile::fail(int error) noexcept {
  if (failed_) return;
  failed_ = true;
  errno_ = error != 0 ? error : EIO;
}

Expected<void> ExportFile::close() {
  if (!file_) return {};
  std::FILE* f = file_.release();
  if (!failed_ && (std::fflush(f) != 0 || std::ferror(f) != 0)) fail(errno);
  if (std::fclose(f) != 0) fail(errno);
  if (failed_) return make_error(path_, "cannot write", std::strerror(errno_));
  return {};
}

}  // namespace mocap::formats_detail
