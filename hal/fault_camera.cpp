// Design: see fault_camera.h. Every path that drops an inner frame releases it at once,
// so the inner camera never runs out of buffers because of an injected fault.
#include "hal/fault_camera.h"

#include <algorithm>

namespace mocap::hal {
namespace {

// What a dequeue of a silent camera does: wait its whole timeout.
void wait_ms(int timeout_ms) noexcept {
  sleep_until_ns(monotonic_ns() + static_cast<std::int64_t>(std::max(timeout_ms, 0)) * 1'000'000);
}

}  // namespace

const char* to_string(Fault f) noexcept {
  switch (f) {
    case Fault::kIoError:
      return "io_error";
    case Fault::kCorruptFrame:
      return "corrupt_frame";
    case Fault::kTimeout:
      return "timeout";
    case Fault::kTruncatedFrame:
      return "truncated_frame";
    case Fault::kDuplicateSequence:
      return "duplicate_sequence";
    case Fault::kSwapOrder:
      return "swap_order";
    case Fault::kTimestampJump:
      return "timestamp_jump";
    case Fault::kReplaceImage:
      return "replace_image";
    case Fault::kStall:
      return "stall";
    case Fault::kSequenceOffset:
      return "sequence_offset";
  }
  return "unknown";
}

FaultCamera::FaultCamera(Camera& inner, const Image* substitute) noexcept
    : inner_(inner), name_("fault:" + inner.name()), substitute_(substitute) {}

Expected<std::unique_ptr<FaultCamera>> FaultCamera::wrap(Camera& inner,
                                                         const std::vector<FaultRule>& rules,
                                                         const Image* substitute) {
  if (rules.size() > kMaxRules) {
    return make_error("FaultCamera", "rules", "at most " + std::to_string(kMaxRules) + " rules");
  }
  std::unique_ptr<FaultCamera> cam(new FaultCamera(inner, substitute));
  for (const FaultRule& r : rules) {
    if (r.count == 0) return make_error("FaultCamera", to_string(r.fault), "count must be >= 1");
    if (r.fault == Fault::kTruncatedFrame && r.value < 0) {
      return make_error("FaultCamera", "truncated_frame", "rows kept must be >= 0");
    }
    if (r.fault == Fault::kReplaceImage && substitute == nullptr) {
      return make_error("FaultCamera", "replace_image", "needs a substitute image");
    }
    cam->rules_[cam->rule_count_++] = r;
  }
  return cam;
}

Expected<std::unique_ptr<FaultCamera>> FaultCamera::wrap(std::unique_ptr<Camera> inner,
                                                         const std::vector<FaultRule>& rules,
                                                         const Image* substitute) {
  if (!inner) return make_error("FaultCamera", "inner", "no camera to wrap");
  auto cam = wrap(*inner, rules, substitute);
  if (cam) (*cam)->owned_ = std::move(inner);
  return cam;
}

Expected<void> FaultCamera::configure(const CameraConfig& config) {
  return inner_.configure(config);
}

Expected<void> FaultCamera::start() {
  const CameraConfig& c = inner_.config();
  if (substitute_ != nullptr &&
      (substitute_->width() != c.width || substitute_->height() != c.height ||
       substitute_->format() != c.format)) {
    return make_error(name_, "replace_image",
                      "substitute image differs from the camera's size or format");
  }
  swap_pending_ = false;
  has_last_ = false;
  stall_calls_.fill(0);
  return inner_.start();
}

void FaultCamera::stop() noexcept { inner_.stop(); }

std::uint64_t FaultCamera::injected_total() const noexcept {
  std::uint64_t n = 0;
  for (const rt::Counter& c : injected_) n += c.get();
  return n;
}

const FaultRule* FaultCamera::rule_for(std::uint64_t index) const noexcept {
  for (std::size_t i = 0; i < rule_count_; ++i) {
    const FaultRule& r = rules_[i];
    if (r.fault != Fault::kStall && index >= r.first && index - r.first < r.count) return &r;
  }
  return nullptr;
}

bool FaultCamera::stalled(std::uint64_t index) noexcept {
  for (std::size_t i = 0; i < rule_count_; ++i) {
    const FaultRule& r = rules_[i];
    if (r.fault != Fault::kStall || r.first != index || stall_calls_[i] >= r.count) continue;
    if (r.count != FaultRule::kForever) ++stall_calls_[i];
    return true;
  }
  return false;
}

CameraStatus FaultCamera::dequeue(Frame& out, int timeout_ms) noexcept {
  if (stalled(seen_.get())) {  // the inner camera is not asked: its frames pile up there
    injected_[static_cast<std::size_t>(Fault::kStall)].add();
    wait_ms(timeout_ms);
    return CameraStatus::kTimeout;
  }
  const CameraStatus st = inner_.dequeue(out, timeout_ms);
  if (st != CameraStatus::kOk) return st;
  return apply(out, timeout_ms);
}

CameraStatus FaultCamera::apply(Frame& f, int timeout_ms) noexcept {
  const std::uint64_t index = seen_.get();
  seen_.add();
  if (swap_pending_) {  // the second frame of a kSwapOrder pair
    f.sequence -= 1;
    swap_pending_ = false;
  } else if (const FaultRule* r = rule_for(index); r != nullptr) {
    injected_[static_cast<std::size_t>(r->fault)].add();
    switch (r->fault) {
      case Fault::kIoError:
        inner_.release(f);
        return CameraStatus::kIoError;
      case Fault::kCorruptFrame:
        inner_.release(f);
        return CameraStatus::kCorruptFrame;
      case Fault::kTimeout:  // a stopped camera: the call waits its whole timeout
        inner_.release(f);
        wait_ms(timeout_ms);
        return CameraStatus::kTimeout;
      case Fault::kTruncatedFrame:
        f.image.height = static_cast<int>(std::min<std::int64_t>(r->value, f.image.height));
        break;
      case Fault::kDuplicateSequence:
        if (has_last_) f.sequence = last_sequence_;
        break;
      case Fault::kSwapOrder:  // this frame takes the next one's number, and vice versa
        f.sequence += 1;
        swap_pending_ = true;
        last_sequence_ = f.sequence;
        has_last_ = true;
        return CameraStatus::kOk;
      case Fault::kTimestampJump:
        f.timestamp_ns += r->value;
        break;
      case Fault::kReplaceImage:
        f.image = substitute_->view();
        break;
      case Fault::kSequenceOffset:
        f.sequence += static_cast<std::uint64_t>(r->value);
        break;
      case Fault::kStall:  // held before the inner dequeue (stalled()); never a frame rule
        break;
    }
  }
  last_sequence_ = f.sequence;
  has_last_ = true;
  return CameraStatus::kOk;
}

}  // namespace mocap::hal
