// Design: fast, exact fixed-point text for the per-frame text outputs (markers.csv, TRC):
// std::to_chars with chars_format::fixed gives the same digits as printf("%.*f") (both
// are exact, ties to even) without printf's format parsing and locale, into a caller's
// buffer; noexcept and allocation-free.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <system_error>

namespace mocap::formats_detail {

// Writes `v` with `decimals` decimals at p; returns the end, or nullptr when it does not
// fit before `end`.
inline char* put_fixed(char* p, char* end, double v, int decimals) noexcept {
  if (!p) return nullptr;
  const std::to_chars_result r = std::to_chars(p, end, v, std::chars_format::fixed, decimals);
  return r.ec == std::errc{} ? r.ptr : nullptr;
}

inline char* put_int(char* p, char* end, std::int64_t v) noexcept {
  if (!p) return nullptr;
  const std::to_chars_result r = std::to_chars(p, end, v);
  return r.ec == std::errc{} ? r.ptr : nullptr;
}

inline char* put_text(char* p, char* end, std::string_view s) noexcept {
  if (!p || static_cast<std::size_t>(end - p) < s.size()) return nullptr;
  std::memcpy(p, s.data(), s.size());
  return p + s.size();
}

}  // namespace mocap::formats_detail
