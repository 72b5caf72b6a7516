// Design: see fake_v4l2.h. Only what the backend uses is implemented; anything else
// fails with ENOTTY as the kernel does for unknown ioctls.
#include "tests/hal/fake_v4l2.h"

#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace mocap::hal::test {

int FakeV4l2::fail(int err) {
  errno = err;
  return -1;
}

int FakeV4l2::open(const char* p, int) {
  if (path != p) return fail(ENOENT);
  ++open_fds;
  format_.pixelformat = modes.front().fourcc;
  format_.width = modes.front().width;
  format_.height = modes.front().height;
  return kFd;
}

int FakeV4l2::close(int fd) {
  if (fd != kFd) return fail(EBADF);
  --open_fds;
  return 0;
}

bool FakeV4l2::emit_frame(std::uint8_t fill, bool error_flag, std::uint32_t bytesused_override) {
  const std::uint32_t seq = sequence_++;
  clock_ns_ += 10'000'000;  // 100 fps
  if (!streaming || queued_.empty()) return false;
  const std::uint32_t i = queued_.front();
  queued_.erase(queued_.begin());
  Buf& b = buffers_[i];
  std::fill(b.memory.begin(), b.memory.end(), fill);
  b.info.sequence = seq;
  b.info.timestamp.tv_sec = clock_ns_ / 1'000'000'000;
  b.info.timestamp.tv_usec = (clock_ns_ % 1'000'000'000) / 1000;
  b.info.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_DONE |
                 (error_flag ? V4L2_BUF_FLAG_ERROR : 0u);
  b.info.bytesused = bytesused_override != 0 ? bytesused_override : format_.sizeimage;
  b.state = BufState::kDone;
  done_.push_back(i);
  last_timestamp_ns = clock_ns_;
  return true;
}

int FakeV4l2::ioctl(int fd, unsigned long request, void* arg) {
  if (fd != kFd) return fail(EBADF);
  if (unplugged) return fail(ENODEV);
  return do_ioctl(request, arg);
}

int FakeV4l2::do_ioctl(unsigned long request, void* arg) {
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      *cap = v4l2_capability{};
      std::strncpy(reinterpret_cast<char*>(cap->driver), "fake", sizeof cap->driver);
      cap->capabilities = capabilities | V4L2_CAP_DEVICE_CAPS;
      cap->device_caps = capabilities;
      return 0;
    }
    case VIDIOC_S_FMT: {
      if (streaming || !buffers_.empty()) return fail(EBUSY);
      auto* f = static_cast<v4l2_format*>(arg);
      if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return fail(EINVAL);
      // Like a driver: the requested mode if offered, else the first one.
      Mode m = modes.front();
      for (const Mode& cand : modes) {
        if (cand.fourcc == f->fmt.pix.pixelformat && cand.width == f->fmt.pix.width &&
            cand.height == f->fmt.pix.height) {
          m = cand;
        }
      }
      const std::uint32_t bpp = m.fourcc == V4L2_PIX_FMT_Y16 ? 2 : 1;
      format_ = v4l2_pix_format{};
      format_.width = m.width;
      format_.height = m.height;
      format_.pixelformat = m.fourcc;
      format_.field = V4L2_FIELD_NONE;
      format_.bytesperline = m.width * bpp + row_padding_bytes;
      format_.sizeimage = format_.bytesperline * m.height;
      f->fmt.pix = format_;
      return 0;
    }
    case VIDIOC_G_FMT: {
      auto* f = static_cast<v4l2_format*>(arg);
      if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return fail(EINVAL);
      f->fmt.pix = format_;
      return 0;
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto* p = static_cast<v4l2_streamparm*>(arg);
      if (request == VIDIOC_S_PARM) {
        if (!timeperframe) return fail(EINVAL);
        // The fake rounds to whole frames per second, as many sensors do.
        const v4l2_fract want = p->parm.capture.timeperframe;
        const std::uint32_t fps =
            want.numerator == 0 ? 30 : (want.denominator + want.numerator / 2) / want.numerator;
        timeperframe_ = v4l2_fract{1, std::max<std::uint32_t>(fps, 1)};
      }
      p->parm.capture = v4l2_captureparm{};
      p->parm.capture.capability = timeperframe ? V4L2_CAP_TIMEPERFRAME : 0;
      p->parm.capture.timeperframe = timeperframe_;
      return 0;
    }
    case VIDIOC_QUERYCTRL: {
      auto* q = static_cast<v4l2_queryctrl*>(arg);
      auto it = controls.end();
      if (q->id & V4L2_CTRL_FLAG_NEXT_CTRL) {
        it = controls.upper_bound(q->id & ~V4L2_CTRL_FLAG_NEXT_CTRL);
      } else {
        it = controls.find(q->id);
      }
      if (it == controls.end()) return fail(EINVAL);
      *q = v4l2_queryctrl{};
      q->id = it->first;
      q->type = it->second.type;
      std::strncpy(reinterpret_cast<char*>(q->name), it->second.name.c_str(), sizeof q->name - 1);
      q->minimum = it->second.minimum;
      q->maximum = it->second.maximum;
      q->step = it->second.step;
      return 0;
    }
    case VIDIOC_QUERYMENU: {
      auto* m = static_cast<v4l2_querymenu*>(arg);
      auto it = controls.find(m->id);
      if (it == controls.end() || m->index >= it->second.menu.size()) return fail(EINVAL);
      std::strncpy(reinterpret_cast<char*>(m->name), it->second.menu[m->index].c_str(),
                   sizeof m->name - 1);
      return 0;
    }
    case VIDIOC_S_CTRL:
    case VIDIOC_G_CTRL: {
      auto* c = static_cast<v4l2_control*>(arg);
      auto it = controls.find(c->id);
      if (it == controls.end()) return fail(EINVAL);
      if (request == VIDIOC_G_CTRL) {
        c->value = it->second.value;
        return 0;
      }
      if (c->value < it->second.minimum || c->value > it->second.maximum) return fail(ERANGE);
      if (c->id == software_trigger_id && software_trigger_id != 0) {
        emit_frame(static_cast<std::uint8_t>(sequence_ & 0xffu));
        return 0;
      }
      it->second.value = c->value;
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* r = static_cast<v4l2_requestbuffers*>(arg);
      if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
      if (streaming) return fail(EBUSY);
      if (r->count == 0) {
        if (mapped > 0) return fail(EBUSY);
        buffers_.clear();
        queued_.clear();
        done_.clear();
        return 0;
      }
      r->count = std::min(r->count, max_buffers);
      buffers_.assign(r->count, Buf{});
      queued_.reserve(r->count);
      done_.reserve(r->count);
      for (std::uint32_t i = 0; i < r->count; ++i) {
        buffers_[i].memory.assign(format_.sizeimage, 0);
        buffers_[i].info.index = i;
        buffers_[i].info.length = format_.sizeimage;
        buffers_[i].info.m.offset = i * 4096u * 1024u;
      }
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= buffers_.size()) return fail(EINVAL);
      b->length = buffers_[b->index].info.length;
      b->m.offset = buffers_[b->index].info.m.offset;
      return 0;
    }
    case VIDIOC_QBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= buffers_.size() || buffers_[b->index].state != BufState::kUser)
        return fail(EINVAL);
      buffers_[b->index].state = BufState::kQueued;
      queued_.push_back(b->index);
      return 0;
    }
    case VIDIOC_DQBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (fail_next_dqbuf_errno != 0) {
        const int e = fail_next_dqbuf_errno;
        fail_next_dqbuf_errno = 0;
        return fail(e);
      }
      if (!streaming) return fail(EINVAL);
      if (done_.empty()) return fail(EAGAIN);
      const std::uint32_t i = done_.front();
      done_.erase(done_.begin());
      buffers_[i].state = BufState::kUser;
      *b = buffers_[i].info;
      return 0;
    }
    case VIDIOC_STREAMON:
      if (buffers_.empty()) return fail(EINVAL);
      streaming = true;
      return 0;
    case VIDIOC_STREAMOFF:
      streaming = false;
      for (Buf& b : buffers_) b.state = BufState::kUser;
      queued_.clear();
      done_.clear();
      return 0;
    default:
      return fail(ENOTTY);
  }
}

void* FakeV4l2::mmap(std::size_t length, int, int, int fd, off_t offset) {
  if (fd != kFd) {
    errno = EBADF;
    return MAP_FAILED;
  }
  for (Buf& b : buffers_) {
    if (static_cast<off_t>(b.info.m.offset) == offset && length <= b.memory.size()) {
      ++mapped;
      return b.memory.data();
    }
  }
  errno = EINVAL;
  return MAP_FAILED;
}

int FakeV4l2::munmap(void*, std::size_t) {
  --mapped;
  return 0;
}

int FakeV4l2::poll(pollfd* fds, nfds_t, int) {
  if (unplugged) {
    fds[0].revents = POLLERR;
    return 1;
  }
  if (done_.empty() && auto_emit) emit_frame(static_cast<std::uint8_t>(sequence_ & 0xffu));
  if (done_.empty()) {
    fds[0].revents = 0;
    return 0;  // timeout (the fake does not sleep)
  }
  fds[0].revents = POLLIN;
  return 1;
}

}  // namespace mocap::hal::test
