// Design: helpers of the fuzz entry points (fuzz_targets.h): the in-memory file behind
// the path-based loaders and the invariant-failure abort.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {

void fuzz_check_failed(const char* what) {
  std::fprintf(stderr, "fuzz invariant failed: %s\n", what);
  std::abort();
}

const char* fuzz_file(const std::uint8_t* data, std::size_t size) {
  thread_local int fd = -1;
  thread_local char path[64];
  if (fd < 0) {
    fd = ::memfd_create("mocap_fuzz", MFD_CLOEXEC);
    if (fd < 0) fuzz_check_failed("memfd_create");
    std::snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
  }
  if (::ftruncate(fd, 0) != 0) fuzz_check_failed("ftruncate");
  std::size_t done = 0;
  while (done < size) {
    const ssize_t w = ::pwrite(fd, data + done, size - done, static_cast<off_t>(done));
    if (w <= 0) fuzz_check_failed("pwrite");
    done += static_cast<std::size_t>(w);
  }
  return path;
}

}  // namespace mocap::fuzz
