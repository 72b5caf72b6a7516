// Design: see libcamera_camera.h. Thread roles: libcamera's thread only runs
// on_request_completed (SpscRing producer + eventfd write); everything else runs on the
// thread that drives the Camera (ring consumer). The request/buffer tables are built
// before Camera::start() and torn down after Camera::stop() (which returns once every
// request has completed or been cancelled), so both threads may read them meanwhile.
#include "hal/libcamera_camera.h"

#include <libcamera/libcamera.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>

#include "rt/spsc_ring.h"

namespace mocap::hal {

namespace lc = libcamera;

struct LibcameraSession::Impl {
  lc::CameraManager manager;
};

LibcameraSession::LibcameraSession() : impl_(std::make_unique<Impl>()) {}
LibcameraSession::~LibcameraSession() { impl_->manager.stop(); }

Expected<std::shared_ptr<LibcameraSession>> LibcameraSession::get() {
  static std::mutex mutex;
  static std::weak_ptr<LibcameraSession> running;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto s = running.lock()) return s;
  std::shared_ptr<LibcameraSession> s(new LibcameraSession());
  if (const int r = s->impl_->manager.start(); r < 0) {
    return make_error("libcamera", "",
                      std::string("cannot start the camera manager: ") + std::strerror(-r));
  }
  running = s;
  return s;
}

std::vector<std::string> LibcameraSession::camera_ids() const {
  std::vector<std::string> ids;
  for (const auto& cam : impl_->manager.cameras()) ids.push_back(cam->id());
  return ids;
}

struct LibcameraCamera::Impl {
  struct Mapped {
    void* base = nullptr;
    std::size_t length = 0;
    const std::uint8_t* data = nullptr;
    bool held = false;
  };

  std::shared_ptr<LibcameraSession> session;
  std::shared_ptr<lc::Camera> camera;
  std::string name;
  CameraState state = CameraState::kClosed;
  CameraConfig config;
  std::string notice;
  CameraCounters counters;
  std::unique_ptr<lc::CameraConfiguration> lc_config;
  lc::Stream* stream = nullptr;
  int stride_bytes = 0;
  std::uint16_t maxval = 255;
  std::unique_ptr<lc::FrameBufferAllocator> allocator;
  std::vector<std::unique_ptr<lc::Request>> requests;
  std::vector<Mapped> mapped;
  std::unique_ptr<rt::SpscRing<std::uint32_t>> completed;  // libcamera thread -> capture thread
  int event_fd = -1;
  std::atomic<bool> disconnected{false};
  bool have_sequence = false;
  std::uint64_t last_sequence = 0;

  // libcamera's thread.
  void on_request_completed(lc::Request* request) {
    completed->try_push(static_cast<std::uint32_t>(request->cookie()));  // capacity >= requests
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(event_fd, &one, sizeof one);
  }
  void on_disconnected() {
    // release: pairs with the acquire load in dequeue (nothing else is published).
    disconnected.store(true, std::memory_order_release);
  }

  void teardown() noexcept {
    for (Mapped& m : mapped) {
      if (m.base != nullptr) ::munmap(m.base, m.length);
    }
    mapped.clear();
    requests.clear();
    if (allocator && stream != nullptr) allocator->free(stream);
    allocator.reset();
    completed.reset();
    if (event_fd >= 0) ::close(event_fd);
    event_fd = -1;
  }

  CameraStatus requeue(std::uint32_t index) noexcept {
    lc::Request* r = requests[index].get();
    r->reuse(lc::Request::ReuseBuffers);
    const int q = camera->queueRequest(r);
    if (q < 0) {
      counters.errors.add();
      if (q == -ENODEV) {
        state = CameraState::kError;
        return CameraStatus::kDeviceLost;
      }
      return CameraStatus::kIoError;
    }
    return CameraStatus::kOk;
  }
};

Expected<std::unique_ptr<LibcameraCamera>> LibcameraCamera::open(
    std::shared_ptr<LibcameraSession> session, const std::string& id) {
  if (!session) return make_error("libcamera", "", "no session");
  const auto cameras = session->impl().manager.cameras();
  if (cameras.empty()) return make_error("libcamera", "", "no camera found");
  std::shared_ptr<lc::Camera> cam = session->impl().manager.get(id);
  if (!cam && !id.empty() && id.find_first_not_of("0123456789") == std::string::npos &&
      id.size() < 4) {
    const std::size_t index = std::stoul(id);
    if (index < cameras.size()) cam = cameras[index];
  }
  if (!cam) {
    std::string available;
    for (const auto& c : cameras) available += (available.empty() ? "" : ", ") + c->id();
    return make_error("libcamera", "",
                      "camera '" + id + "' not found (available: " + available + ")");
  }
  if (const int r = cam->acquire(); r < 0) {
    return make_error("libcamera", cam->id(), std::string("cannot acquire: ") + std::strerror(-r));
  }
  auto impl = std::make_unique<Impl>();
  impl->session = std::move(session);
  impl->camera = cam;
  impl->name = "libcamera:" + cam->id();
  Impl* raw = impl.get();
  cam->disconnected.connect(raw, &Impl::on_disconnected);
  return std::unique_ptr<LibcameraCamera>(new LibcameraCamera(std::move(impl)));
}

LibcameraCamera::LibcameraCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LibcameraCamera::~LibcameraCamera() {
  stop();
  impl_->camera->disconnected.disconnect(impl_.get());
  impl_->camera->release();
}

const std::string& LibcameraCamera::name() const noexcept { return impl_->name; }
CameraState LibcameraCamera::state() const noexcept { return impl_->state; }
const CameraConfig& LibcameraCamera::config() const noexcept { return impl_->config; }
const std::string& LibcameraCamera::notice() const noexcept { return impl_->notice; }
const CameraCounters& LibcameraCamera::counters() const noexcept { return impl_->counters; }

Expected<void> LibcameraCamera::configure(const CameraConfig& want) {
  Impl& d = *impl_;
  if (d.state == CameraState::kStreaming)
    return make_error(d.name, "configure", "stop streaming first");
  if (d.state == CameraState::kError)
    return make_error(d.name, "configure", "camera failed: reopen it");
  if (want.width <= 0 || want.height <= 0) return make_error(d.name, "size", "must be positive");
  if (want.buffer_count < 2 || want.buffer_count > 32)
    return make_error(d.name, "buffer_count", "must be in 2..32");
  d.state = CameraState::kClosed;
  d.notice.clear();
  d.config = want;
  d.lc_config = d.camera->generateConfiguration({lc::StreamRole::Raw});
  if (!d.lc_config || d.lc_config->empty()) return make_error(d.name, "format", "no raw stream");
  lc::StreamConfiguration& sc = d.lc_config->at(0);
  const lc::PixelFormat want_format =
      want.format == PixelFormat::kMono8 ? lc::formats::R8 : lc::formats::R12;
  sc.pixelFormat = want_format;
  sc.size = lc::Size(static_cast<unsigned>(want.width), static_cast<unsigned>(want.height));
  sc.bufferCount = static_cast<unsigned>(want.buffer_count);
  if (d.lc_config->validate() == lc::CameraConfiguration::Invalid) {
    return make_error(d.name, "format", "the camera rejects a raw " + sc.toString() + " stream");
  }
  const bool mono16 = sc.pixelFormat == lc::formats::R10 || sc.pixelFormat == lc::formats::R12;
  const bool format_ok =
      want.format == PixelFormat::kMono8 ? sc.pixelFormat == lc::formats::R8 : mono16;
  if (!format_ok || sc.size.width != static_cast<unsigned>(want.width) ||
      sc.size.height != static_cast<unsigned>(want.height)) {
    return make_error(d.name, "format",
                      "camera offers " + sc.toString() + " for the requested " +
                          std::to_string(want.width) + "x" + std::to_string(want.height) + "-" +
                          want_format.toString());
  }
  if (const int r = d.camera->configure(d.lc_config.get()); r < 0) {
    return make_error(d.name, "format", std::string("configure failed: ") + std::strerror(-r));
  }
  d.stream = sc.stream();
  d.stride_bytes = static_cast<int>(sc.stride);
  d.maxval =
      want.format == PixelFormat::kMono8 ? 255 : (sc.pixelFormat == lc::formats::R10 ? 1023 : 4095);
  d.config.buffer_count = static_cast<int>(sc.bufferCount);
  if (want.trigger == TriggerMode::kExternal) {
    d.notice =
        d.name +
        ": trigger: libcamera has no trigger control; the sensor driver must be set to external "
        "trigger (pair frames by timestamp)";
  } else if (want.trigger == TriggerMode::kSoftware) {
    d.config.trigger = TriggerMode::kFreeRun;
    d.notice = d.name + ": trigger: libcamera has no software trigger: camera free-runs";
  }
  d.state = CameraState::kConfigured;
  return {};
}

Expected<void> LibcameraCamera::start() {
  Impl& d = *impl_;
  if (d.state != CameraState::kConfigured) {
    return make_error(d.name, "start",
                      std::string("camera is ") + to_string(d.state) + ", not configured");
  }
  d.allocator = std::make_unique<lc::FrameBufferAllocator>(d.camera);
  if (d.allocator->allocate(d.stream) < 0) {
    d.teardown();
    return make_error(d.name, "start", "cannot allocate buffers");
  }
  const auto& buffers = d.allocator->buffers(d.stream);
  d.completed =
      std::make_unique<rt::SpscRing<std::uint32_t>>(rt::next_power_of_two_at_least(buffers.size()));
  d.event_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (d.event_fd < 0) {
    const int e = errno;
    d.teardown();
    return make_error(d.name, "start", std::string("eventfd: ") + std::strerror(e));
  }
  const std::size_t frame_bytes =
      static_cast<std::size_t>(d.stride_bytes) * static_cast<std::size_t>(d.config.height);
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    lc::FrameBuffer* fb = buffers[i].get();
    const lc::FrameBuffer::Plane& plane = fb->planes().front();
    Impl::Mapped m;
    m.length = plane.offset + plane.length;
    m.base = ::mmap(nullptr, m.length, PROT_READ, MAP_SHARED, plane.fd.get(), 0);
    if (m.base == MAP_FAILED || plane.length < frame_bytes) {
      const int e = errno;
      if (m.base != MAP_FAILED) ::munmap(m.base, m.length);
      d.teardown();
      return make_error(d.name, "start",
                        m.base == MAP_FAILED ? std::string("mmap: ") + std::strerror(e)
                                             : std::string("buffer smaller than a frame"));
    }
    m.data = static_cast<const std::uint8_t*>(m.base) + plane.offset;
    d.mapped.push_back(m);
    std::unique_ptr<lc::Request> req = d.camera->createRequest(i);
    if (!req || req->addBuffer(d.stream, fb) < 0) {
      d.teardown();
      return make_error(d.name, "start", "cannot create request " + std::to_string(i));
    }
    d.requests.push_back(std::move(req));
  }
  lc::ControlList controls;
  if (d.config.exposure_us > 0) {
    controls.set(lc::controls::AeEnable, false);
    controls.set(lc::controls::ExposureTime, static_cast<std::int32_t>(d.config.exposure_us));
  }
  if (d.config.gain >= 0.0)
    controls.set(lc::controls::AnalogueGain, static_cast<float>(d.config.gain));
  if (d.config.frame_rate_hz > 0.0 && d.config.trigger == TriggerMode::kFreeRun) {
    const auto frame_us = static_cast<std::int64_t>(std::llround(1e6 / d.config.frame_rate_hz));
    const std::int64_t limits[2] = {frame_us, frame_us};
    controls.set(lc::controls::FrameDurationLimits, lc::Span<const std::int64_t, 2>(limits));
  }
  d.camera->requestCompleted.connect(&d, &Impl::on_request_completed);
  if (const int r = d.camera->start(&controls); r < 0) {
    d.camera->requestCompleted.disconnect(&d);
    d.teardown();
    return make_error(d.name, "start", std::string("cannot start: ") + std::strerror(-r));
  }
  for (auto& req : d.requests) {
    if (const int r = d.camera->queueRequest(req.get()); r < 0) {
      d.camera->stop();
      d.camera->requestCompleted.disconnect(&d);
      d.teardown();
      return make_error(d.name, "start",
                        std::string("cannot queue a request: ") + std::strerror(-r));
    }
  }
  d.have_sequence = false;
  d.state = CameraState::kStreaming;
  return {};
}

void LibcameraCamera::stop() noexcept {
  Impl& d = *impl_;
  if (d.state != CameraState::kStreaming && d.state != CameraState::kError) return;
  if (d.requests.empty()) return;
  d.camera->stop();  // returns when every request has completed or been cancelled
  d.camera->requestCompleted.disconnect(&d);
  d.teardown();
  if (d.state == CameraState::kStreaming) d.state = CameraState::kConfigured;
}

CameraStatus LibcameraCamera::trigger() noexcept {
  if (impl_->state != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  return CameraStatus::kUnsupported;
}

CameraStatus LibcameraCamera::dequeue(Frame& out, int timeout_ms) noexcept {
  Impl& d = *impl_;
  // acquire: pairs with the release store in on_disconnected.
  if (d.disconnected.load(std::memory_order_acquire) && d.state == CameraState::kStreaming) {
    d.state = CameraState::kError;
    d.counters.errors.add();
  }
  if (d.state == CameraState::kError) return CameraStatus::kDeviceLost;
  if (d.state != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  std::uint32_t index = 0;
  if (!d.completed->try_pop(index)) {
    pollfd p{d.event_fd, POLLIN, 0};
    const int pr = ::poll(&p, 1, timeout_ms);
    if (pr == 0) {
      d.counters.timeouts.add();
      return CameraStatus::kTimeout;
    }
    if (pr < 0) {
      if (errno == EINTR) return CameraStatus::kAgain;
      d.counters.errors.add();
      return CameraStatus::kIoError;
    }
    std::uint64_t count = 0;
    [[maybe_unused]] const ssize_t n = ::read(d.event_fd, &count, sizeof count);
    if (!d.completed->try_pop(index)) return CameraStatus::kAgain;
  }
  if (index >= d.requests.size()) {
    d.counters.errors.add();
    return CameraStatus::kIoError;
  }
  lc::Request* req = d.requests[index].get();
  const lc::FrameBuffer* fb = req->findBuffer(d.stream);
  const lc::FrameMetadata& md = fb->metadata();
  if (req->status() != lc::Request::RequestComplete ||
      md.status != lc::FrameMetadata::FrameSuccess) {
    d.counters.errors.add();
    const CameraStatus s = d.requeue(index);
    return s == CameraStatus::kOk ? CameraStatus::kCorruptFrame : s;
  }
  const std::uint64_t sequence =
      d.have_sequence
          ? d.last_sequence + static_cast<std::uint32_t>(
                                  md.sequence - static_cast<std::uint32_t>(d.last_sequence))
          : md.sequence;
  if (d.have_sequence && sequence > d.last_sequence + 1)
    d.counters.dropped.add(sequence - d.last_sequence - 1);
  d.have_sequence = true;
  d.last_sequence = sequence;
  const std::optional<std::int64_t> sensor_ts = req->metadata().get(lc::controls::SensorTimestamp);
  d.mapped[index].held = true;
  out.image = ImageView{d.mapped[index].data, d.config.width,  d.config.height,
                        d.stride_bytes,       d.config.format, d.maxval};
  out.sequence = sequence;
  out.timestamp_ns = sensor_ts ? *sensor_ts : static_cast<std::int64_t>(md.timestamp);
  out.received_ns = monotonic_ns();
  out.buffer_index = index;
  out.missing = false;
  d.counters.frames.add();
  return CameraStatus::kOk;
}

CameraStatus LibcameraCamera::release(const Frame& frame) noexcept {
  Impl& d = *impl_;
  if (d.state == CameraState::kError) return CameraStatus::kDeviceLost;
  if (d.state != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (frame.buffer_index >= d.mapped.size() || !d.mapped[frame.buffer_index].held) {
    d.counters.errors.add();
    return CameraStatus::kInvalidBuffer;
  }
  d.mapped[frame.buffer_index].held = false;
  return d.requeue(frame.buffer_index);
}

}  // namespace mocap::hal
