// Design: see node_wire.h.
#include "pipeline/node/node_wire.h"

#include <bit>
#include <cmath>
#include <cstring>

namespace mocap::node {
namespace {

// Little-endian scalar I/O through memcpy (bit-exact for the floats).
template <class T>
void put(std::uint8_t*& p, T v) noexcept {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    for (std::size_t i = 0; i < sizeof(T); ++i) p[i] = raw[sizeof(T) - 1 - i];
  } else {
    std::memcpy(p, raw, sizeof(T));
  }
  p += sizeof(T);
}

template <class T>
T get(const std::uint8_t*& p) noexcept {
  std::uint8_t raw[sizeof(T)];
  if constexpr (std::endian::native == std::endian::big) {
    for (std::size_t i = 0; i < sizeof(T); ++i) raw[i] = p[sizeof(T) - 1 - i];
  } else {
    std::memcpy(raw, p, sizeof(T));
  }
  p += sizeof(T);
  T v;
  std::memcpy(&v, raw, sizeof(T));
  return v;
}

constexpr int kMaxCoordinatePx = 1 << 20;  // far beyond any sensor; bounds the bbox

bool finite_in(double v, double lo, double hi) noexcept {
  return std::isfinite(v) && v >= lo && v <= hi;
}

bool valid_blob(const detect::Blob& b) noexcept {
  const double lim = kMaxCoordinatePx;
  return finite_in(b.x_px, -lim, lim) && finite_in(b.y_px, -lim, lim) &&
         finite_in(b.area_px, 0.0, lim * lim) && std::isfinite(b.sum_dn) &&
         b.x_min >= -kMaxCoordinatePx && b.x_max <= kMaxCoordinatePx && b.x_min <= b.x_max &&
         b.y_min >= -kMaxCoordinatePx && b.y_max <= kMaxCoordinatePx && b.y_min <= b.y_max &&
         finite_in(b.major_axis_px, 0.0, lim) && finite_in(b.minor_axis_px, 0.0, lim) &&
         finite_in(b.roundness, 0.0, 1.0) && finite_in(b.eccentricity, 0.0, 1.0) &&
         finite_in(b.orientation_rad, -4.0, 4.0);
}

}  // namespace

const char* to_string(WireError e) noexcept {
  switch (e) {
    case WireError::kOk:
      return "ok";
    case WireError::kBadVersion:
      return "unknown version";
    case WireError::kBadFlags:
      return "bad flags";
    case WireError::kBadName:
      return "bad name";
    case WireError::kBadSize:
      return "size does not match blob_count";
    case WireError::kBadValue:
      return "bad value";
    case WireError::kOversized:
      return "too many blobs";
  }
  return "?";
}

bool valid_name(const char (&name)[kNameBytes]) noexcept {
  std::size_t n = 0;
  while (n < kNameBytes && name[n] != '\0') {
    const auto c = static_cast<unsigned char>(name[n]);
    if (c < 0x21 || c > 0x7e) return false;
    ++n;
  }
  return n > 0 && n < kNameBytes;
}

void set_name(char (&name)[kNameBytes], const char* text) noexcept {
  std::memset(name, 0, kNameBytes);
  if (text == nullptr) return;
  for (std::size_t i = 0; i + 1 < kNameBytes && text[i] != '\0'; ++i) name[i] = text[i];
}

std::uint32_t encode_blobs(const detect::BlobList& blobs, std::uint8_t* out,
                           std::size_t capacity) noexcept {
  std::size_t n = static_cast<std::size_t>(blobs.size());
  if (n > kMaxBlobsPerMessage) n = kMaxBlobsPerMessage;
  if (n > capacity / kBlobRecordBytes) n = capacity / kBlobRecordBytes;
  std::uint8_t* p = out;
  for (std::size_t i = 0; i < n; ++i) {
    const detect::Blob& b = blobs[i];
    put(p, b.x_px);
    put(p, b.y_px);
    put(p, b.area_px);
    put(p, b.sum_dn);
    put(p, b.peak_dn);
    put(p, b.background_dn);
    put(p, static_cast<std::int32_t>(b.x_min));
    put(p, static_cast<std::int32_t>(b.y_min));
    put(p, static_cast<std::int32_t>(b.x_max));
    put(p, static_cast<std::int32_t>(b.y_max));
    put(p, b.major_axis_px);
    put(p, b.minor_axis_px);
    put(p, b.roundness);
    put(p, b.eccentricity);
    put(p, b.orientation_rad);
    put(p, b.flags);
  }
  return static_cast<std::uint32_t>(n);
}

WireError check_header(const WireHeader& h) noexcept {
  if (h.version != kWireVersion) return WireError::kBadVersion;
  if ((h.flags & ~kWireKnownFlags) != 0) return WireError::kBadFlags;
  if ((h.flags & (kWireEndOfStream | kWireMissing)) != 0 && h.blob_count != 0)
    return WireError::kBadFlags;
  if (!valid_name(h.node) || !valid_name(h.camera)) return WireError::kBadName;
  if (h.blob_count > kMaxBlobsPerMessage) return WireError::kOversized;
  if (!std::isfinite(h.background_dn) || !std::isfinite(h.noise_dn) ||
      !std::isfinite(h.threshold_dn))
    return WireError::kBadValue;
  return WireError::kOk;
}

WireError decode_frame(const WireHeader& h, const std::uint8_t* data, std::size_t size,
                       detect::BlobList& out) noexcept {
  out.clear();
  if (const WireError e = check_header(h); e != WireError::kOk) return e;
  if (h.blob_count > static_cast<std::uint32_t>(out.capacity())) return WireError::kOversized;
  // No multiplication overflow: blob_count <= kMaxBlobsPerMessage.
  if (size != static_cast<std::size_t>(h.blob_count) * kBlobRecordBytes ||
      (size > 0 && data == nullptr))
    return WireError::kBadSize;
  const std::uint8_t* p = data;
  for (std::uint32_t i = 0; i < h.blob_count; ++i) {
    detect::Blob b;
    b.x_px = get<double>(p);
    b.y_px = get<double>(p);
    b.area_px = get<float>(p);
    b.sum_dn = get<float>(p);
    b.peak_dn = get<std::uint16_t>(p);
    b.background_dn = get<std::uint16_t>(p);
    b.x_min = get<std::int32_t>(p);
    b.y_min = get<std::int32_t>(p);
    b.x_max = get<std::int32_t>(p);
    b.y_max = get<std::int32_t>(p);
    b.major_axis_px = get<float>(p);
    b.minor_axis_px = get<float>(p);
    b.roundness = get<float>(p);
    b.eccentricity = get<float>(p);
    b.orientation_rad = get<float>(p);
    b.flags = get<std::uint32_t>(p);
    if (!valid_blob(b)) {
      out.clear();
      return WireError::kBadValue;
    }
    out.push_back(b);
  }
  out.set_levels({h.background_dn, h.noise_dn, h.threshold_dn});
  return WireError::kOk;
}

}  // namespace mocap::node
