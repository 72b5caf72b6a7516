// Design: see node_camera.h.
#include "pipeline/node/node_camera.h"

#include <algorithm>

#include "core/clock.h"

namespace mocap::node {

Expected<std::unique_ptr<NodeCamera>> NodeCamera::open(std::shared_ptr<NodeLink> link,
                                                       const std::string& device, int max_blobs,
                                                       int timeout_ms) {
  const std::size_t slash = device.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == device.size() ||
      device.find('/', slash + 1) != std::string::npos)
    return make_error(device, "device", "expected NODE/CAMERA");
  if (max_blobs < 1 || max_blobs > static_cast<int>(kMaxBlobsPerMessage))
    return make_error(
        device, "detection.max_blobs",
        "must be in 1.." + std::to_string(kMaxBlobsPerMessage) + " with node cameras");
  auto k = link->add_camera(device.substr(0, slash), device.substr(slash + 1), 32, max_blobs);
  if (!k) return k.error();
  return std::unique_ptr<NodeCamera>(new NodeCamera(std::move(link), *k, device, timeout_ms));
}

NodeCamera::NodeCamera(std::shared_ptr<NodeLink> link, int index, std::string device,
                       int timeout_ms)
    : CameraBase("node:" + device),
      link_(std::move(link)),
      index_(index),
      timeout_ns_(static_cast<std::int64_t>(timeout_ms) * 1'000'000) {}

NodeCamera::~NodeCamera() { stop(); }

hal::CameraConfig NodeCamera::native_config() const {
  hal::CameraConfig c;
  c.trigger = hal::TriggerMode::kSoftware;
  c.buffer_count = 8;
  return c;
}

Expected<void> NodeCamera::configure(const hal::CameraConfig& config) {
  if (auto r = check_not_streaming(); !r) return r;
  // The inbox holds 32 messages; the pipeline holds at most buffer_count of them.
  if (auto r = check_buffer_count(config.buffer_count, 24); !r) return r;
  config_ = config;
  central_ = config.trigger == hal::TriggerMode::kSoftware;
  state_ = hal::CameraState::kConfigured;
  return {};
}

Expected<void> NodeCamera::start() {
  if (auto r = check_configured(); !r) return r;
  if (auto r = link_->start(); !r) return r;
  notice_ = link_->notice();
  eos_ = down_ = held_valid_ = have_last_ = false;
  missing_run_ = 0;
  triggered_ = next_ = 0;
  std::fill(std::begin(delivered_real_), std::end(delivered_real_), 0);
  reset_sequence();
  state_ = hal::CameraState::kStreaming;
  return {};
}

void NodeCamera::stop() noexcept {
  if (state_ != hal::CameraState::kStreaming) return;
  if (held_valid_) link_->inbox(index_).release(held_);
  held_valid_ = false;
  rt::SlotHandle h;
  while (link_->inbox(index_).pop(h)) link_->inbox(index_).release(h);
  link_->stop();
  state_ = hal::CameraState::kConfigured;
}

hal::CameraStatus NodeCamera::trigger() noexcept { return post(monotonic_ns(), 0); }

std::int64_t NodeCamera::trigger_lead_ns() const noexcept {
  return central_ ? link_->trigger_lead_ns() : 0;
}

hal::CameraStatus NodeCamera::trigger_at(std::int64_t at_ns) noexcept { return post(at_ns, at_ns); }

hal::CameraStatus NodeCamera::post(std::int64_t instant_ns, std::int64_t fire_ns) noexcept {
  if (state_ != hal::CameraState::kStreaming) return hal::CameraStatus::kNotStreaming;
  if (!central_) return hal::CameraStatus::kUnsupported;
  trigger_ns_[triggered_ % kWindow] = instant_ns;
  link_->trigger(triggered_, fire_ns);
  ++triggered_;
  return hal::CameraStatus::kOk;
}

bool NodeCamera::take() noexcept {
  if (held_valid_) return true;
  rt::SlotPool<Received>& inbox = link_->inbox(index_);
  while (inbox.pop(held_)) {
    const WireHeader& h = inbox[held_].header;
    if ((h.flags & kWireEndOfStream) != 0) {
      eos_ = true;
      inbox.release(held_);
      continue;
    }
    const std::uint64_t k = h.frame_number;
    bool stale = false;
    if (central_) {
      if (k >= triggered_) {
        stale = true;  // not triggered (yet): a node of another run, or a restarted one
        late_.add();
      } else if (k < next_) {
        stale = true;
        (next_ - k <= kWindow && delivered_real_[k % kWindow] == k + 1 ? duplicates_ : late_).add();
      }
    } else if (have_last_ && k <= last_number_) {
      if (mapped_capture_ns(h) > last_mapped_ns_) {  // captured later: the node restarted
        have_last_ = false;
        reconnects_.add();
      } else {
        stale = true;
        (k == last_number_ ? duplicates_ : late_).add();
      }
    }
    if (down_ && !stale) {  // the node is back
      down_ = false;
      reconnects_.add();
    }
    if (stale) {
      if (down_) {
        down_ = false;
        reconnects_.add();
      }
      inbox.release(held_);
      continue;
    }
    held_valid_ = true;
    return true;
  }
  return false;
}

std::int64_t NodeCamera::mapped_capture_ns(const WireHeader& h) noexcept {
  if ((h.flags & kWireReplay) != 0 || h.realtime_offset_ns == 0) return h.capture_ns;
  // A live camera's CLOCK_MONOTONIC on the node -> this host's, through CLOCK_REALTIME
  // (PTP-synchronised across the PCs: pair_by timestamp compares these).
  const std::int64_t central_offset = realtime_ns() - monotonic_ns();
  return h.capture_ns + h.realtime_offset_ns - central_offset;
}

void NodeCamera::deliver_held(hal::Frame& out) noexcept {
  const Received& r = link_->inbox(index_)[held_];
  const std::uint64_t k = r.header.frame_number;
  out = hal::Frame{};
  out.sequence = k;
  out.timestamp_ns = mapped_capture_ns(r.header);
  last_mapped_ns_ = out.timestamp_ns;
  out.received_ns = r.received_ns;
  // The latencies start at the central trigger (the node's round trip included).
  out.delivered_ns = central_ ? trigger_ns_[k % kWindow] : r.received_ns;
  out.buffer_index = held_;
  out.missing = (r.header.flags & kWireMissing) != 0;
  out.blobs = out.missing ? nullptr : &r.blobs;
  if (have_last_ && k > last_number_)
    period_ns_ =
        (r.header.capture_ns - last_capture_ns_) / static_cast<std::int64_t>(k - last_number_);
  have_last_ = true;
  last_number_ = k;
  last_capture_ns_ = r.header.capture_ns;
  if (central_) {
    delivered_real_[k % kWindow] = k + 1;
    next_ = k + 1;
  }
  held_valid_ = false;
  missing_run_ = 0;
  note_sequence(k);
  counters_.frames.add();
}

void NodeCamera::deliver_missing(hal::Frame& out) noexcept {
  const std::uint64_t k = next_++;
  out = hal::Frame{};
  out.sequence = k;
  // The time it would have had (the identification's motion prior needs a time).
  out.timestamp_ns =
      have_last_ ? last_capture_ns_ + period_ns_ * static_cast<std::int64_t>(k - last_number_) : 0;
  out.received_ns = monotonic_ns();
  out.delivered_ns = trigger_ns_[k % kWindow];
  out.buffer_index = kNoSlot;
  out.missing = true;
  delivered_real_[k % kWindow] = 0;
  if (++missing_run_ >= 3) down_ = true;
  counters_.missing.add();
}

hal::CameraStatus NodeCamera::dequeue(hal::Frame& out, int timeout_ms) noexcept {
  if (state_ != hal::CameraState::kStreaming) return hal::CameraStatus::kNotStreaming;
  const std::int64_t deadline = monotonic_ns() + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
  rt::Doorbell& bell = link_->bell();
  for (;;) {
    const std::uint32_t seen = bell.snapshot();
    const bool have = take();
    if (!central_) {
      if (have) {
        deliver_held(out);
        return hal::CameraStatus::kOk;
      }
      if (eos_) return hal::CameraStatus::kEndOfStream;
    } else if (next_ < triggered_) {  // frame next_ is due
      if (have) {
        if (link_->inbox(index_)[held_].header.frame_number == next_) {
          deliver_held(out);
        } else {
          deliver_missing(out);  // the node skipped it: a later frame came first
        }
        return hal::CameraStatus::kOk;
      }
      if (eos_) return hal::CameraStatus::kEndOfStream;
      // Missing: down, or late past the timeout, and some node answered this trigger.
      if ((down_ || monotonic_ns() - trigger_ns_[next_ % kWindow] > timeout_ns_) &&
          link_->received_end() > next_) {
        deliver_missing(out);
        return hal::CameraStatus::kOk;
      }
    } else if (eos_) {
      return hal::CameraStatus::kEndOfStream;
    }
    const std::int64_t now = monotonic_ns();
    if (now >= deadline) {
      counters_.timeouts.add();
      return hal::CameraStatus::kTimeout;
    }
    std::int64_t wait_ns = deadline - now;
    if (central_ && next_ < triggered_) {
      // Until frame next_'s timeout, then until a message (which may show that another
      // node answered: received_end) or the deadline: never a 1 ns poll past the timeout.
      const std::int64_t until_timeout_ns = trigger_ns_[next_ % kWindow] + timeout_ns_ - now + 1;
      if (until_timeout_ns > 0) wait_ns = std::min(wait_ns, until_timeout_ns);
    }
    bell.wait(seen, wait_ns);
  }
}

hal::CameraStatus NodeCamera::release(const hal::Frame& frame) noexcept {
  if (frame.buffer_index == kNoSlot) return hal::CameraStatus::kOk;
  if (frame.buffer_index >= link_->inbox(index_).slot_count()) {
    counters_.errors.add();
    return hal::CameraStatus::kInvalidBuffer;
  }
  link_->inbox(index_).release(frame.buffer_index);
  return hal::CameraStatus::kOk;
}

}  // namespace mocap::node
