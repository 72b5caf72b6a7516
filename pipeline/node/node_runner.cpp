// Design: see node_runner.h.
#include "pipeline/node/node_runner.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "core/clock.h"
#include "rt/cpu_relax.h"

namespace mocap::node {

Expected<std::unique_ptr<NodeRunner>> NodeRunner::create(std::vector<NodeCameraSpec> cameras,
                                                         const detect::DetectorConfig& detect,
                                                         const NodeOptions& options,
                                                         NodeSender& sender) {
  const int n = static_cast<int>(cameras.size());
  if (n < 1 || n > kMaxNodeCameras)
    return make_error(
        "mocap node", "cameras",
        std::to_string(n) + " cameras, expected 1.." + std::to_string(kMaxNodeCameras));
  if (detect.max_blobs > static_cast<int>(kMaxBlobsPerMessage))
    return make_error(
        "mocap node", "detection.max_blobs",
        "at most " + std::to_string(kMaxBlobsPerMessage) + " on a node (one message)");
  if (!(options.trigger_rate_hz > 0.0))
    return make_error("mocap node", "pipeline.trigger_rate_hz", "must be > 0");
  int central = 0;
  for (const NodeCameraSpec& s : cameras) central += s.central ? 1 : 0;
  if (options.detect_threads < 0 || options.detect_threads > central)
    return make_error("mocap node", "node.detect_threads",
                      std::to_string(options.detect_threads) + " workers for " +
                          std::to_string(central) + " cameras with trigger: central");
  std::unique_ptr<NodeRunner> r(new NodeRunner(std::move(cameras), options, sender));
  for (int c = 0; c < n; ++c)
    if (r->cams_[static_cast<std::size_t>(c)].central) r->central_.push_back(c);
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  r->workers_ =
      detect_workers(options.detect_threads, central, cpus > 0 ? static_cast<int>(cpus) : 1);
  sender.set_trigger_wakeups(r->workers_);
  for (const NodeCameraSpec& s : r->cams_) {
    if (s.camera == nullptr) return make_error("mocap node", "cameras", "camera missing");
    const hal::CameraConfig& cc = s.camera->config();
    auto d = detect::BlobDetector::create(detect, cc.width, cc.height);
    if (!d) return make_error("mocap node", "detection (" + s.name + ")", d.error().message);
    r->lists_.push_back(d->make_blob_list());
    r->detectors_.push_back(std::move(d).value());
    r->states_.push_back(std::make_unique<CamState>());
    auto w = std::make_unique<WireFrame>();
    set_name(w->header.node, options.node_name.c_str());
    set_name(w->header.camera, s.name.c_str());
    if (!valid_name(w->header.node) || !valid_name(w->header.camera))
      return make_error("mocap node", "node.name / camera " + s.name,
                        "names are 1..63 printable characters without spaces");
    r->staging_.push_back(std::move(w));
  }
  return r;
}

int detect_workers(int detect_threads, int central, int cpus) noexcept {
  if (central <= 0) return 0;
  if (detect_threads > 0) return std::min(detect_threads, central);
  return std::clamp(cpus, 1, central);
}

NodeRunner::~NodeRunner() { stop(); }

Expected<void> NodeRunner::start() {
  if (running_) return make_error("mocap node", "start", "already running");
  notes_.clear();
  stop_.store(false, std::memory_order_relaxed);  // no thread runs yet
  ended_.store(0, std::memory_order_relaxed);
  for (std::size_t c = 0; c < cams_.size(); ++c) {
    if (auto r = cams_[c].camera->start(); !r) {
      for (std::size_t s = 0; s < c; ++s) cams_[s].camera->stop();
      return r.error();
    }
  }
  for (auto& s : states_) {
    s->ended = false;
    s->has_staged = false;
    s->held.store(false, std::memory_order_relaxed);  // no thread runs yet
  }
  running_ = true;
  const int cameras = static_cast<int>(cams_.size());
  for (int k = 0; k < cameras + workers_; ++k) {
    const bool worker = k >= cameras;
    if (!worker && cams_[static_cast<std::size_t>(k)].central) continue;  // a worker's
    const std::string name =
        worker ? "mocap-ndet" + std::to_string(k - cameras) : "mocap-node" + std::to_string(k);
    rt::ThreadSpec spec{name, -1, options_.realtime ? 80 : 0};
    auto t = worker ? rt::start_thread(spec, [this] { work(); })
                    : rt::start_thread(spec, [this, k] { run(k); });
    if (!t) {
      stop();
      return t.error();
    }
    if (!t->setup().note.empty()) notes_.push_back(t->setup().note);
    threads_.push_back(std::move(t).value());
  }
  return {};
}

void NodeRunner::stop() noexcept {
  if (!running_) return;
  // release: the camera threads' and workers' acquire loads see the stop.
  stop_.store(true, std::memory_order_release);
  sender_.trigger_bell().ring(std::max(workers_, 1));
  for (rt::RtThread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
  for (const NodeCameraSpec& s : cams_) s.camera->stop();
  running_ = false;
}

std::uint64_t NodeRunner::published() const noexcept {
  std::uint64_t n = 0;
  for (const auto& s : states_) n += s->frames.get();
  return n;
}

std::string NodeRunner::report() const {
  std::string out;
  for (std::size_t c = 0; c < cams_.size(); ++c) {
    const CamState& s = *states_[c];
    char line[256];
    std::snprintf(line, sizeof line,
                  "camera %s: frames %llu, queue_dropped %llu, timeouts %llu, errors %llu, "
                  "detect_overflow %llu, skipped %llu, behind %llu\n",
                  cams_[c].name.c_str(), static_cast<unsigned long long>(s.frames.get()),
                  static_cast<unsigned long long>(sender_.queue(static_cast<int>(c)).dropped()),
                  static_cast<unsigned long long>(s.timeouts.get()),
                  static_cast<unsigned long long>(s.errors.get()),
                  static_cast<unsigned long long>(s.overflow.get()),
                  static_cast<unsigned long long>(
                      cams_[c].seekable != nullptr ? cams_[c].seekable->skipped() : 0),
                  static_cast<unsigned long long>(s.behind.get()));
    out += line;
  }
  return out;
}

std::int64_t NodeRunner::take_triggers(int c) noexcept {
  CamState& st = *states_[static_cast<std::size_t>(c)];
  hal::Camera& cam = *cams_[static_cast<std::size_t>(c)].camera;
  for (;;) {
    if (!st.has_staged) {
      if (st.count >= std::size(st.pending) || !sender_.triggers(c).try_pop(st.staged))
        return kNoInstant;
      st.has_staged = true;
    }
    // A scheduled trigger waits for its instant (the triggers behind it too: in order).
    if (st.staged.fire_ns != 0 && st.staged.fire_ns > monotonic_ns()) return st.staged.fire_ns;
    st.has_staged = false;
    if (cam.trigger() != hal::CameraStatus::kOk) {
      st.errors.add();
      continue;
    }
    st.triggers.add();
    st.pending[(st.head + st.count) % std::size(st.pending)] = st.staged;
    ++st.count;
  }
}

void NodeRunner::wait_for(rt::Doorbell& bell, std::uint32_t seen,
                          std::int64_t instant_ns) noexcept {
  // Asleep until kFireSpinNs before the instant (a trigger or the stop rings earlier),
  // then spinning, so the cameras fire at the instant and not a wake-up later.
  const std::int64_t asleep_ns = instant_ns - kFireSpinNs - monotonic_ns();
  if (asleep_ns > 0) {
    bell.wait(seen, asleep_ns);
    return;  // the caller looks again
  }
  while (monotonic_ns() < instant_ns && !stop_.load(std::memory_order_acquire)) rt::cpu_relax();
}

void NodeRunner::send(int c, const hal::Frame* f, std::uint16_t flags,
                      const TriggerStamp& t) noexcept {
  const auto ci = static_cast<std::size_t>(c);
  CamState& st = *states_[ci];
  WireFrame& w = *staging_[ci];
  WireHeader& h = w.header;
  detect::BlobList& list = lists_[ci];
  list.clear();
  const bool image = f != nullptr && !f->missing && !f->image.empty();
  if (image && !detectors_[ci].detect(f->image, list)) st.overflow.add();
  if (f != nullptr && !image) flags |= kWireMissing;
  if (cams_[ci].replay) flags |= kWireReplay;
  h.flags = flags;
  h.frame_number = t.number;
  h.capture_ns = f != nullptr ? f->timestamp_ns : 0;
  h.trigger_sent_ns = t.sent_ns;
  h.trigger_received_ns = t.received_ns;
  h.detected_ns = monotonic_ns();
  const hal::CameraCounters& cc = cams_[ci].camera->counters();
  h.health = {st.frames.get(), cc.dropped.get(), sender_.queue(c).dropped(), st.overflow.get(),
              st.timeouts.get()};
  const detect::BlobList::Levels& lv = list.levels();
  h.background_dn = lv.background_dn;
  h.noise_dn = lv.noise_dn;
  h.threshold_dn = lv.threshold_dn;
  h.blob_count = image ? encode_blobs(list, w.blobs, sizeof w.blobs) : 0;
  sender_.queue(c).push(w);  // drop-oldest: counted in the queue's dropped(); woken by the caller
}

bool NodeRunner::deliver(int c, hal::CameraStatus s, hal::Frame& f) noexcept {
  const auto ci = static_cast<std::size_t>(c);
  CamState& st = state(c);
  if (s == hal::CameraStatus::kTimeout || s == hal::CameraStatus::kAgain) {
    if (s == hal::CameraStatus::kTimeout) st.timeouts.add();
    return false;
  }
  if (s == hal::CameraStatus::kEndOfStream) {
    send(c, nullptr, kWireEndOfStream, TriggerStamp{});
    st.ended = true;
    ended_.fetch_add(1, std::memory_order_acq_rel);  // finished() acquires it
    return true;
  }
  if (s != hal::CameraStatus::kOk) {
    st.errors.add();
    return false;
  }
  TriggerStamp t{f.sequence, 0, 0};
  if (cams_[ci].central && st.count > 0) {
    t = st.pending[st.head];
    st.head = (st.head + 1) % static_cast<std::uint32_t>(std::size(st.pending));
    --st.count;
    st.behind_noted = false;
  }
  st.frames.add();
  send(c, &f, 0, t);
  if (cams_[ci].camera->release(f) != hal::CameraStatus::kOk) st.errors.add();
  return false;
}

bool NodeRunner::claim(int c) noexcept {
  std::atomic<bool>& held = state(c).held;
  // relaxed pre-check: a held camera is skipped without writing its line; acquire on the
  // exchange: the previous holder's writes (camera, state, queue) happen before ours.
  return !held.load(std::memory_order_relaxed) && !held.exchange(true, std::memory_order_acquire);
}

void NodeRunner::unclaim(int c) noexcept {
  // release: this holder's writes happen before the next holder's acquire exchange.
  state(c).held.store(false, std::memory_order_release);
}

bool NodeRunner::play(int c) noexcept {
  const auto ci = static_cast<std::size_t>(c);
  CamState& st = state(c);
  take_triggers(c);
  if (st.count == 0) return false;
  // A replay plays the frame the oldest pending trigger names (a no-op in step).
  if (hal::ReplayCamera* r = cams_[ci].seekable;
      r != nullptr && r->seek(st.pending[st.head].number) == hal::CameraStatus::kUnsupported &&
      !st.behind_noted) {
    st.behind.add();  // once per trigger
    st.behind_noted = true;
  }
  hal::Frame f;
  (void)deliver(c, cams_[ci].camera->dequeue(f, 20), f);
  return true;
}

void NodeRunner::work() noexcept {
  rt::Doorbell& bell = sender_.trigger_bell();
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = bell.snapshot();
    // Every pending trigger whose instant came first (the exposures start together), then
    // one frame per camera; a camera held by another worker is that worker's.
    // The camera's state (ended included) is read and written only by its holder.
    std::int64_t next_instant = kNoInstant;
    for (const int c : central_) {
      if (!claim(c)) continue;
      if (!state(c).ended) next_instant = std::min(next_instant, take_triggers(c));
      unclaim(c);
    }
    bool played = false;
    for (const int c : central_) {
      if (!claim(c)) continue;
      if (!state(c).ended) played = play(c) || played;
      unclaim(c);
    }
    // One wake-up of the sender for the frames of this pass: it writes them together.
    if (played)
      sender_.wake();
    else if (next_instant != kNoInstant)
      wait_for(bell, seen, next_instant);
    else
      bell.wait(seen, 10'000'000);
  }
}

void NodeRunner::run(int c) noexcept {
  const auto ci = static_cast<std::size_t>(c);
  hal::Camera& cam = *cams_[ci].camera;
  CamState& st = state(c);
  const bool software = cam.config().trigger == hal::TriggerMode::kSoftware;
  const auto period_ns = static_cast<std::int64_t>(1e9 / options_.trigger_rate_hz);
  std::int64_t next_ns = monotonic_ns();
  while (!stop_.load(std::memory_order_acquire)) {
    int timeout_ms = 20;
    if (software) {
      const std::int64_t now = monotonic_ns();
      if (now >= next_ns) {
        if (cam.trigger() != hal::CameraStatus::kOk) st.errors.add();
        st.triggers.add();
        next_ns += period_ns;
        if (next_ns < now) next_ns = now + period_ns;  // overran: re-phase
      }
      timeout_ms =
          static_cast<int>(std::clamp<std::int64_t>((next_ns - monotonic_ns()) / 1'000'000, 0, 20));
    }
    hal::Frame f;
    const hal::CameraStatus s = cam.dequeue(f, timeout_ms);
    const bool ended = deliver(c, s, f);
    if (s == hal::CameraStatus::kOk || ended) sender_.wake();  // a message was pushed
    if (ended) break;
  }
}

}  // namespace mocap::node
