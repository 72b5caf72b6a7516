// Design: every system call of the V4L2 backend goes through this small interface, so
// that tests drive the backend with a fake device (format negotiation, buffer cycling,
// timeouts, EIO/ENODEV/EAGAIN) on a machine without cameras. Calls follow the POSIX
// convention: -1 (MAP_FAILED for mmap) with errno set on failure.
#pragma once

#include <poll.h>
#include <sys/types.h>

#include <cstddef>
#include <memory>

namespace mocap::hal {

struct V4l2Sys {
  virtual ~V4l2Sys() = default;
  virtual int open(const char* path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) = 0;
  virtual int munmap(void* addr, std::size_t length) = 0;
  virtual int poll(pollfd* fds, nfds_t nfds, int timeout_ms) = 0;
};

// The real kernel interface.
std::shared_ptr<V4l2Sys> real_v4l2_sys();

}  // namespace mocap::hal
