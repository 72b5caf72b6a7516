// Design: synthetic marker images for the detector tests and benchmarks, rendered
// independently of the simulator: discs (or ellipses) with exact pixel-area coverage
// (pixels fully inside/outside are decided analytically, edge pixels by 32x32
// supersampling), summed light from overlapping markers, optional Gaussian blur,
// Gaussian noise, rounding and clipping to the image's maxval. The true centres are
// known exactly. Pixel centre of the top-left pixel = (0, 0).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/image.h"

namespace mocap::detect::test {

struct Spot {
  double x, y;          // centre (px)
  double radius_px;     // semi-axis along the spot's own x (a disc when aspect == 1)
  double amplitude_dn;  // brightness above background
  double aspect = 1.0;  // minor/major semi-axis ratio
  double angle_rad = 0.0;
};

struct SynthParams {
  int width = 320;
  int height = 240;
  PixelFormat format = PixelFormat::kMono8;
  std::uint16_t maxval = 255;
  double background_dn = 20.0;
  double noise_sigma_dn = 2.0;
  double blur_sigma_px = 0.0;
  std::uint32_t seed = 1;
  int stride_pad_bytes = 0;  // extra bytes per row (tests stride handling)
};

// Coverage of pixel (px, py) by an ellipse spot, in [0, 1].
inline double coverage(const Spot& s, int px, int py) {
  const double a = s.radius_px;
  const double b = s.radius_px * s.aspect;
  const double c = std::cos(s.angle_rad), sn = std::sin(s.angle_rad);
  auto inside = [&](double x, double y) {
    const double dx = x - s.x, dy = y - s.y;
    const double u = dx * c + dy * sn, v = -dx * sn + dy * c;
    return (u * u) / (a * a) + (v * v) / (b * b) <= 1.0;
  };
  // Quick decisions from the distance of the pixel centre (pixel half-diagonal 0.7072).
  const double d = std::hypot(px - s.x, py - s.y);
  if (d > a + 0.7072) return 0.0;
  if (d < b - 0.7072) return 1.0;
  constexpr int kSub = 32;
  int n = 0;
  for (int j = 0; j < kSub; ++j) {
    for (int i = 0; i < kSub; ++i) {
      n += inside(px - 0.5 + (i + 0.5) / kSub, py - 0.5 + (j + 0.5) / kSub) ? 1 : 0;
    }
  }
  return static_cast<double>(n) / (kSub * kSub);
}

// Gaussian blur of a light field (p.blur_sigma_px; none when 0), separable, clamped edges.
inline void blur(std::vector<double>& f, const SynthParams& p) {
  if (p.blur_sigma_px <= 0.0) return;
  const int r = static_cast<int>(std::ceil(3.0 * p.blur_sigma_px));
  std::vector<double> k(static_cast<std::size_t>(2 * r + 1));
  double sum = 0.0;
  for (int i = -r; i <= r; ++i)
    sum += k[i + r] = std::exp(-0.5 * i * i / (p.blur_sigma_px * p.blur_sigma_px));
  for (double& v : k) v /= sum;
  std::vector<double> tmp(f.size());
  for (int pass = 0; pass < 2; ++pass) {
    for (int y = 0; y < p.height; ++y) {
      for (int x = 0; x < p.width; ++x) {
        double acc = 0.0;
        for (int i = -r; i <= r; ++i) {
          const int xx = std::clamp(pass == 0 ? x + i : x, 0, p.width - 1);
          const int yy = std::clamp(pass == 0 ? y : y + i, 0, p.height - 1);
          acc += k[i + r] * f[static_cast<std::size_t>(yy) * p.width + xx];
        }
        tmp[static_cast<std::size_t>(y) * p.width + x] = acc;
      }
    }
    f.swap(tmp);
  }
}

// Linear light (background + spots, blurred) before noise and quantisation.
inline std::vector<double> render_light(const std::vector<Spot>& spots, const SynthParams& p) {
  std::vector<double> f(static_cast<std::size_t>(p.width) * static_cast<std::size_t>(p.height),
                        p.background_dn);
  for (const Spot& s : spots) {
    const int r = static_cast<int>(std::ceil(s.radius_px)) + 2;
    for (int y = std::max(0, static_cast<int>(s.y) - r);
         y <= std::min(p.height - 1, static_cast<int>(s.y) + r); ++y) {
      for (int x = std::max(0, static_cast<int>(s.x) - r);
           x <= std::min(p.width - 1, static_cast<int>(s.x) + r); ++x) {
        f[static_cast<std::size_t>(y) * p.width + x] += s.amplitude_dn * coverage(s, x, y);
      }
    }
  }
  blur(f, p);
  return f;
}

// An owned image buffer with optional row padding, and its view.
struct SynthImage {
  std::vector<std::uint8_t> bytes;
  ImageView view;
};

inline SynthImage quantise(const std::vector<double>& light, const SynthParams& p) {
  SynthImage im;
  const int bpp = bytes_per_pixel(p.format);
  const int stride = p.width * bpp + p.stride_pad_bytes;
  im.bytes.assign(static_cast<std::size_t>(stride) * p.height + 64, 0xAB);
  std::mt19937 rng(p.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) {
      double v = light[static_cast<std::size_t>(y) * p.width + x];
      if (p.noise_sigma_dn > 0.0) v += p.noise_sigma_dn * noise(rng);
      const auto q =
          static_cast<std::uint16_t>(std::clamp(std::lround(v), 0L, static_cast<long>(p.maxval)));
      std::uint8_t* row = im.bytes.data() + static_cast<std::size_t>(y) * stride;
      if (p.format == PixelFormat::kMono8) {
        row[x] = static_cast<std::uint8_t>(q);
      } else {
        reinterpret_cast<std::uint16_t*>(row)[x] = q;
      }
    }
  }
  im.view = ImageView{im.bytes.data(), p.width, p.height, stride, p.format, p.maxval};
  return im;
}

inline SynthImage render(const std::vector<Spot>& spots, const SynthParams& p) {
  return quantise(render_light(spots, p), p);
}

// A ball's image: a disc of radius r at (x, y) and amplitude amp, with an optional dark
// rod: a bar of width rod_w whose axis leaves the disc's centre at angle phi (image x
// towards y), hiding the disc from 0.6 r outwards (a wand's rod entering the ball).
// Blur, noise and quantisation as p says.
inline SynthImage ball_with_rod(const SynthParams& p, double x, double y, double r, double amp,
                                double rod_w, double phi) {
  std::vector<double> f(static_cast<std::size_t>(p.width) * p.height, 0.0);
  const Spot disc{x, y, r, amp};
  const double ca = std::cos(phi), sa = std::sin(phi);
  const Spot rod{x + ca * (0.6 * r + 10.0),
                 y + sa * (0.6 * r + 10.0),
                 10.0,
                 1.0,
                 rod_w > 0.0 ? 0.5 * rod_w / 10.0 : 1.0,
                 phi};
  const int reach = static_cast<int>(std::ceil(r)) + 2;
  for (int py = std::max(0, static_cast<int>(y) - reach);
       py <= std::min(p.height - 1, static_cast<int>(y) + reach); ++py) {
    for (int px = std::max(0, static_cast<int>(x) - reach);
         px <= std::min(p.width - 1, static_cast<int>(x) + reach); ++px) {
      const double hidden = rod_w > 0.0 ? coverage(rod, px, py) : 0.0;
      f[static_cast<std::size_t>(py) * p.width + px] =
          disc.amplitude_dn * coverage(disc, px, py) * (1.0 - hidden);
    }
  }
  blur(f, p);
  for (double& v : f) v += p.background_dn;
  return quantise(f, p);
}

// Random well-separated discs (centres at least min_gap_px apart, inside the margin).
inline std::vector<Spot> random_discs(int n, const SynthParams& p, double r_min, double r_max,
                                      double amp_min, double amp_max, double min_gap_px,
                                      std::uint32_t seed, int margin_px = 4) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ur(r_min, r_max), ua(amp_min, amp_max);
  std::vector<Spot> out;
  for (int tries = 0; tries < 100000 && static_cast<int>(out.size()) < n; ++tries) {
    const double r = ur(rng);
    std::uniform_real_distribution<double> ux(margin_px + r, p.width - 1 - margin_px - r);
    std::uniform_real_distribution<double> uy(margin_px + r, p.height - 1 - margin_px - r);
    Spot s{ux(rng), uy(rng), r, ua(rng)};
    bool ok = true;
    for (const Spot& o : out)
      ok = ok && std::hypot(o.x - s.x, o.y - s.y) > o.radius_px + r + min_gap_px;
    if (ok) out.push_back(s);
  }
  return out;
}

}  // namespace mocap::detect::test
