// Design: see cpu_latency.h. The kernel reads the request as a binary 32-bit integer
// (Documentation/power/pm_qos_interface.rst: "a 32-bit integer ... or a hex string"); a
// short write is an error, not a partial request.
#include "rt/cpu_latency.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace mocap::rt {

CpuLatencyRequest& CpuLatencyRequest::operator=(CpuLatencyRequest&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = o.fd_;
    o.fd_ = -1;
  }
  return *this;
}

std::string CpuLatencyRequest::request(int max_latency_us, const std::string& device) {
  release();
  if (max_latency_us < 0 || max_latency_us > kMaxCpuLatencyUs) {
    return device + ": CPU latency " + std::to_string(max_latency_us) + " us is outside 0.." +
           std::to_string(kMaxCpuLatencyUs) + ": not requested";
  }
  const int fd = ::open(device.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    return device + ": " + std::strerror(e) +
           ": CPU idle states not limited, wake-ups may add latency (needs root or the "
           "udev rule of deploy/60-mocap-cpu-latency.rules)";
  }
  const std::int32_t value = max_latency_us;
  const ssize_t n = ::write(fd, &value, sizeof value);
  if (n != static_cast<ssize_t>(sizeof value)) {
    const int e = n < 0 ? errno : EIO;
    ::close(fd);
    return device + ": write: " + std::strerror(e) + ": CPU idle states not limited";
  }
  fd_ = fd;
  return {};
}

void CpuLatencyRequest::release() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

}  // namespace mocap::rt
