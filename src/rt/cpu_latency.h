// Design: keeps the CPUs out of deep idle states while the live pipeline runs, through
// the kernel's PM QoS CPU latency request (/dev/cpu_dma_latency, what real-time
// deployments and cyclictest use). Every stage sleeps on a futex between frames; a CPU
// that went idle in the meantime must first wake from its idle state (on a KVM guest: a
// HLT exit to the host and back), which costs up to milliseconds and is paid once per
// stage hand-over. A request of 0 µs makes the idle loop poll instead, so a woken stage
// runs at once; the price is an idle CPU that burns power (only while the request is
// held). The request holds while the file stays open and ends when it is closed (the
// kernel then takes the other holders' minimum, or its default).
// Set-up only: open() and write() at start(), close() at stop(); never on the hot path.
// Not permitted (the device is root's unless a udev rule grants the group, see
// deploy/60-mocap-cpu-latency.rules) or absent: the pipeline runs without it and the
// caller gets ONE line saying so, as rt::lock_memory() does.
#pragma once

#include <cstdint>
#include <string>

namespace mocap::rt {

inline constexpr const char* kCpuLatencyDevice = "/dev/cpu_dma_latency";
inline constexpr int kMaxCpuLatencyUs = 1'000'000;  // configuration range 0..this (-1: none)

class CpuLatencyRequest {
 public:
  CpuLatencyRequest() = default;
  ~CpuLatencyRequest() { release(); }
  CpuLatencyRequest(CpuLatencyRequest&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  CpuLatencyRequest& operator=(CpuLatencyRequest&& o) noexcept;
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;

  // Asks for at most `max_latency_us` (0..kMaxCpuLatencyUs) of wake-up latency on every
  // CPU until release(). Returns an empty note when the request is held, else one line
  // naming the device and the reason (the request is then not held). A previous request
  // of this object is released first.
  std::string request(int max_latency_us, const std::string& device = kCpuLatencyDevice);
  void release() noexcept;
  bool held() const noexcept { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

}  // namespace mocap::rt
