// Design: the simulator's deterministic random numbers. Every random decision is a
// pure function of (seed, frame, camera, item) through SplitMix64 hashing, so a
// rendered image depends only on its scene state and never on the order in which
// frames or cameras are rendered. Streams use xoshiro256** (fast, 2^256 period);
// Gaussians use the polar Box-Muller method. Header-only, noexcept, no allocation.
#pragma once

#include <cmath>
#include <cstdint>

namespace mocap::sim {

inline std::uint64_t splitmix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Order-dependent hash of a key and a value (a new key for a sub-stream).
inline std::uint64_t hash_mix(std::uint64_t key, std::uint64_t value) noexcept {
  std::uint64_t s = key ^ (value * 0xD6E8FEB86659FD93ull);
  splitmix64(s);
  return splitmix64(s);
}

// A uniform number in [0, 1) derived from a key alone (one-shot decisions).
inline double hash_uniform(std::uint64_t key) noexcept {
  std::uint64_t s = key;
  return static_cast<double>(splitmix64(s) >> 11) * 0x1.0p-53;
}

class Rng {
 public:
  explicit Rng(std::uint64_t seed) noexcept {
    std::uint64_t sm = seed;
    for (auto& w : s_) w = splitmix64(sm);
  }

  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1).
  double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * uniform(); }

  // Standard normal N(0, 1).
  double gaussian() noexcept {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = 0.0, v = 0.0, s = 0.0;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * f;
    has_spare_ = true;
    return u * f;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace mocap::sim
