// Design: `mocap preview`'s tap on the live pipeline: keeps a copy of the latest image
// of each camera until every camera has delivered `frames` images, then ignores the
// rest. on_frame runs on the capture thread (noexcept, no allocation: one image per camera,
// 2..kMaxCameras, allocated at construction with the cameras' configured sizes); the owner reads
// the images only after done() turned true and the pipeline was stopped.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/image.h"
#include "pipeline/pipeline.h"

namespace mocap::record {

class SnapshotTap final : public pipeline::FrameTap {
 public:
  // sizes: (width, height, format) of each camera as configured.
  SnapshotTap(const std::vector<hal::CameraConfig>& cameras, std::uint64_t frames)
      : frames_(frames < 1 ? 1 : frames),
        cameras_(std::min(cameras.size(), static_cast<std::size_t>(kMaxCameras))) {
    for (std::size_t c = 0; c < cameras_; ++c)
      images_[c].allocate(cameras[c].width, cameras[c].height, cameras[c].format,
                          cameras[c].format == PixelFormat::kMono8 ? 255 : 65535);
  }

  void on_frame(int camera, const hal::Frame& frame) noexcept override {
    const auto c = static_cast<std::size_t>(camera);
    if (c >= cameras_ || count_[c] >= frames_ || frame.missing || frame.image.empty()) return;
    Image& im = images_[c];
    const ImageView& in = frame.image;
    if (in.width != im.width() || in.height != im.height() || in.format != im.format()) return;
    const auto row = static_cast<std::size_t>(im.stride_bytes());
    for (int y = 0; y < in.height; ++y) std::memcpy(im.row8(y), in.row8(y), row);
    im.set_maxval(in.maxval);
    ++count_[c];
    for (std::size_t k = 0; k < cameras_; ++k)
      if (count_[k] < frames_) return;
    done_.store(true, std::memory_order_release);  // pairs with done()'s acquire
  }

  bool done() const noexcept { return done_.load(std::memory_order_acquire); }
  // Images delivered so far per camera (valid after the pipeline stopped).
  std::uint64_t count(int camera) const noexcept {
    return count_[static_cast<std::size_t>(camera)];
  }
  const Image& image(int camera) const noexcept {
    return images_[static_cast<std::size_t>(camera)];
  }

 private:
  std::uint64_t frames_;
  std::size_t cameras_;
  std::array<Image, kMaxCameras> images_;
  std::array<std::uint64_t, kMaxCameras> count_{};
  std::atomic<bool> done_{false};
};

}  // namespace mocap::record
