// Design: a small deterministic mutator for the CI replay of the fuzz corpus (the GCC
// build has no libFuzzer). Seeded per (seed file, index), so a failing mutation is
// reproducible from its printed number. Mutations: bit flips, random bytes, inserted
// and deleted ranges, duplicated chunks, truncation, and splices of tokens that matter
// to the parsers (digits, signs, "nan", ".inf", YAML brackets and anchors, PGM magic,
// huge numbers, NUL and newline bytes). Several mutations are stacked per input.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mocap::fuzz {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) noexcept : s_(seed) {}
  std::uint64_t next() noexcept {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) noexcept {
    return n == 0 ? 0 : static_cast<std::size_t>(next() % n);
  }

 private:
  std::uint64_t s_;
};

inline std::uint64_t fnv1a(const std::string& s) noexcept {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

inline std::vector<std::uint8_t> mutate(const std::vector<std::uint8_t>& seed, std::uint64_t key) {
  static const char* const kTokens[] = {
      "0",    "-1",    "1e999", ".nan",  ".inf",  "-.inf",      "nan", "99999999999999999999",
      "[",    "]",     "{",     "}",     ": ",    "- ",         "\n",  "\t",
      "&a ",  "*a",    "!!str", "'",     "\"",    "#",          ",",   "P5",
      "P2",   "65535", "256",   "16384", "16385", "4294967297", "\0",  "\xff",
      "0x10", "1.5",   "  ",    "~",     "null",  "? ",         "|",   "---\n"};
  std::vector<std::uint8_t> d = seed;
  SplitMix64 rng(key);
  const int rounds = 1 + static_cast<int>(rng.below(4));
  for (int r = 0; r < rounds; ++r) {
    const std::size_t pos = rng.below(d.size() + 1);
    switch (rng.below(8)) {
      case 0:  // flip a bit
        if (!d.empty()) d[rng.below(d.size())] ^= static_cast<std::uint8_t>(1u << rng.below(8));
        break;
      case 1:  // random byte
        if (!d.empty()) d[rng.below(d.size())] = static_cast<std::uint8_t>(rng.next());
        break;
      case 2: {  // insert random bytes
        const std::size_t n = 1 + rng.below(8);
        for (std::size_t i = 0; i < n; ++i)
          d.insert(d.begin() + static_cast<std::ptrdiff_t>(pos),
                   static_cast<std::uint8_t>(rng.next()));
        break;
      }
      case 3: {  // delete a range
        if (pos < d.size()) {
          const std::size_t n = 1 + rng.below(std::min<std::size_t>(d.size() - pos, 32));
          d.erase(d.begin() + static_cast<std::ptrdiff_t>(pos),
                  d.begin() + static_cast<std::ptrdiff_t>(pos + n));
        }
        break;
      }
      case 4: {  // duplicate a chunk somewhere else
        if (!d.empty()) {
          const std::size_t from = rng.below(d.size());
          const std::size_t n = 1 + rng.below(std::min<std::size_t>(d.size() - from, 64));
          const std::vector<std::uint8_t> chunk(d.begin() + static_cast<std::ptrdiff_t>(from),
                                                d.begin() + static_cast<std::ptrdiff_t>(from + n));
          d.insert(d.begin() + static_cast<std::ptrdiff_t>(rng.below(d.size() + 1)), chunk.begin(),
                   chunk.end());
        }
        break;
      }
      case 5:  // truncate
        d.resize(pos);
        break;
      default: {  // splice a token, sometimes replacing what was there
        const std::string tok = kTokens[rng.below(sizeof kTokens / sizeof kTokens[0])];
        const std::size_t len = tok.empty() ? 1 : tok.size();  // "\0" token is one NUL byte
        if (rng.below(2) && pos < d.size()) {
          d.erase(d.begin() + static_cast<std::ptrdiff_t>(pos),
                  d.begin() + static_cast<std::ptrdiff_t>(std::min(d.size(), pos + len)));
        }
        const std::uint8_t nul = 0;
        const auto* b = tok.empty() ? &nul : reinterpret_cast<const std::uint8_t*>(tok.data());
        d.insert(d.begin() + static_cast<std::ptrdiff_t>(std::min(pos, d.size())), b, b + len);
        break;
      }
    }
  }
  return d;
}

}  // namespace mocap::fuzz
