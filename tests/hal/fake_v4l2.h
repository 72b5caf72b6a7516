// Design: a fake V4L2 capture device behind the V4l2Sys interface, for testing the
// V4L2 backend without hardware. It implements the ioctls the backend uses with the
// kernel's semantics (format negotiation that may adjust size/format, controls with
// ranges and NEXT_CTRL enumeration, mmap buffers, the queued/done/dequeued buffer
// cycle, 32-bit sequence numbers, monotonic timestamps) and lets a test script
// frames (emit_frame), timeouts (poll with nothing done), and errors (EIO once,
// EAGAIN, ENODEV when "unplugged").
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hal/v4l2_sys.h"

namespace mocap::hal::test {

struct FakeControl {
  std::string name;
  std::uint32_t type = V4L2_CTRL_TYPE_INTEGER;
  std::int32_t minimum = 0, maximum = 100, step = 1, value = 0;
  std::vector<std::string> menu;  // for V4L2_CTRL_TYPE_MENU
};

class FakeV4l2 final : public V4l2Sys {
 public:
  // --- device description (set before open) ---
  std::string path = "/dev/video-fake";
  std::uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  // Formats the driver can do; S_FMT picks the requested one if listed, else the first.
  struct Mode {
    std::uint32_t fourcc;
    std::uint32_t width, height;
  };
  std::vector<Mode> modes = {{V4L2_PIX_FMT_GREY, 64, 48}, {V4L2_PIX_FMT_Y16, 64, 48}};
  std::uint32_t row_padding_bytes = 0;
  std::uint32_t max_buffers = 8;
  bool timeperframe = true;
  std::map<std::uint32_t, FakeControl> controls;
  std::uint32_t software_trigger_id = 0;  // a button control: each press emits a frame

  // --- scripting ---
  // Completes the oldest queued buffer with a frame whose pixels are all `fill` (or
  // counts a driver-side drop when no buffer is queued). Returns false on a drop.
  bool emit_frame(std::uint8_t fill, bool error_flag = false, std::uint32_t bytesused_override = 0);
  void skip_sequence(std::uint32_t n) { sequence_ += n; }  // frames lost in the driver
  void set_sequence(std::uint32_t s) { sequence_ = s; }
  bool auto_emit = false;         // poll() emits a frame when none is done
  int fail_next_dqbuf_errno = 0;  // e.g. EIO or EAGAIN, once
  bool unplugged = false;         // every call fails with ENODEV, poll reports POLLERR

  // --- observation ---
  int open_fds = 0;
  int mapped = 0;
  bool streaming = false;
  std::size_t queued_count() const { return queued_.size(); }
  std::size_t done_count() const { return done_.size(); }
  std::uint32_t buffer_count() const { return static_cast<std::uint32_t>(buffers_.size()); }
  std::int64_t last_timestamp_ns = 0;

  // --- V4l2Sys ---
  int open(const char* p, int flags) override;
  int close(int fd) override;
  int ioctl(int fd, unsigned long request, void* arg) override;
  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override;
  int munmap(void* addr, std::size_t length) override;
  int poll(pollfd* fds, nfds_t nfds, int timeout_ms) override;

 private:
  enum class BufState { kUser, kQueued, kDone };
  struct Buf {
    std::vector<std::uint8_t> memory;
    BufState state = BufState::kUser;
    v4l2_buffer info{};
  };
  int fail(int err);
  int do_ioctl(unsigned long request, void* arg);

  v4l2_pix_format format_{};
  v4l2_fract timeperframe_{1, 30};
  std::vector<Buf> buffers_;
  // FIFOs of buffer indices; reserved at REQBUFS so that the fake allocates nothing
  // while streaming (the allocation test counts the backend's and the fake's calls).
  std::vector<std::uint32_t> queued_;
  std::vector<std::uint32_t> done_;
  std::uint32_t sequence_ = 0;
  std::int64_t clock_ns_ = 1'000'000'000;
  static constexpr int kFd = 42;
};

}  // namespace mocap::hal::test
