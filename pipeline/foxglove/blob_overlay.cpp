// Design: see blob_overlay.h.
#include "pipeline/foxglove/blob_overlay.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

namespace mocap::foxglove {

namespace {

std::uint8_t grey_of(std::uint8_t use) noexcept {
  switch (static_cast<publish::BlobUse>(use)) {
    case publish::BlobUse::kMarker:
      return kGreyMarker;
    case publish::BlobUse::kPoint:
      return kGreyPoint;
    case publish::BlobUse::kUnused:
      break;
  }
  return kGreyUnused;
}

}  // namespace

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{static_cast<unsigned char>(bytes[i])} << 16) |
                            (std::uint32_t{static_cast<unsigned char>(bytes[i + 1])} << 8) |
                            std::uint32_t{static_cast<unsigned char>(bytes[i + 2])};
    for (int k = 3; k >= 0; --k) out.push_back(kAlphabet[(v >> (6 * k)) & 63u]);
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t v = std::uint32_t{static_cast<unsigned char>(bytes[i])} << 16;
    if (rest == 2) v |= std::uint32_t{static_cast<unsigned char>(bytes[i + 1])} << 8;
    out.push_back(kAlphabet[(v >> 18) & 63u]);
    out.push_back(kAlphabet[(v >> 12) & 63u]);
    out.push_back(rest == 2 ? kAlphabet[(v >> 6) & 63u] : '=');
    out.push_back('=');
  }
  return out;
}

std::string encode_blob_overlay(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                int camera, std::int64_t stamp_ns) {
  if (camera < 0 || camera >= static_cast<int>(scene.cameras.size())) return {};
  const SceneCamera& cam = scene.cameras[static_cast<std::size_t>(camera)];
  const int w = std::max(1, cam.width_px / kBlobOverlayScale);
  const int h = std::max(1, cam.height_px / kBlobOverlayScale);
  std::string pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), '\0');
  const auto put = [&](int x, int y, std::uint8_t g) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    char& p = pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                     static_cast<std::size_t>(x)];
    p = static_cast<char>(std::max(static_cast<std::uint8_t>(p), g));
  };
  for (int x = 0; x < w; ++x) put(x, 0, kGreyBorder), put(x, h - 1, kGreyBorder);
  for (int y = 0; y < h; ++y) put(0, y, kGreyBorder), put(w - 1, y, kGreyBorder);
  const bool have = camera < std::clamp(frame.camera_count, 0, publish::kMaxResultCameras);
  const publish::CameraBlobs* blobs =
      have ? &frame.cameras[static_cast<std::size_t>(camera)] : nullptr;
  const int first =
      blobs != nullptr ? std::clamp(blobs->first, 0, publish::kMaxResultBlobTotal) : 0;
  const int n =
      blobs != nullptr ? std::clamp(blobs->count, 0, publish::kMaxResultBlobTotal - first) : 0;
  for (int i = 0; i < n; ++i) {
    const publish::ResultBlob& b = frame.blobs[static_cast<std::size_t>(first + i)];
    if (!std::isfinite(b.x_px) || !std::isfinite(b.y_px) || !std::isfinite(b.diameter_px)) continue;
    const double cx = static_cast<double>(b.x_px) / kBlobOverlayScale;
    const double cy = static_cast<double>(b.y_px) / kBlobOverlayScale;
    const double r =
        std::clamp(0.5 * static_cast<double>(b.diameter_px) / kBlobOverlayScale, 0.5, 16.0);
    const std::uint8_t g = grey_of(b.use);
    if (std::abs(cx) > 1e6 || std::abs(cy) > 1e6) continue;
    const int x0 = static_cast<int>(std::floor(cx - r)), x1 = static_cast<int>(std::ceil(cx + r));
    const int y0 = static_cast<int>(std::floor(cy - r)), y1 = static_cast<int>(std::ceil(cy + r));
    bool drawn = false;
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
        if (dx * dx + dy * dy <= r * r) put(x, y, g), drawn = true;
      }
    }
    if (!drawn) put(static_cast<int>(std::floor(cx)), static_cast<int>(std::floor(cy)), g);
  }
  const std::int64_t s = stamp_ns > 0 ? stamp_ns : 0;
  nlohmann::json j = {{"timestamp", {{"sec", s / 1000000000}, {"nsec", s % 1000000000}}},
                      {"frame_id", cam.name},
                      {"width", w},
                      {"height", h},
                      {"encoding", "mono8"},
                      {"step", w},
                      {"data", base64(pixels)}};
  return j.dump();
}

}  // namespace mocap::foxglove
