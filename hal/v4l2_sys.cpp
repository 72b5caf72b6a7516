// Design: the real V4L2 system calls behind V4l2Sys (see v4l2_sys.h).
#include "hal/v4l2_sys.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

namespace mocap::hal {
namespace {

struct RealV4l2Sys final : V4l2Sys {
  int open(const char* path, int flags) override { return ::open(path, flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override { return ::ioctl(fd, request, arg); }
  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    return ::mmap(nullptr, length, prot, flags, fd, offset);
  }
  int munmap(void* addr, std::size_t length) override { return ::munmap(addr, length); }
  int poll(pollfd* fds, nfds_t nfds, int timeout_ms) override {
    return ::poll(fds, nfds, timeout_ms);
  }
};

}  // namespace

std::shared_ptr<V4l2Sys> real_v4l2_sys() {
  static const std::shared_ptr<V4l2Sys> sys = std::make_shared<RealV4l2Sys>();
  return sys;
}

}  // namespace mocap::hal
