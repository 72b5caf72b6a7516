// Design: see text_io.h. Files are read with fopen/fread (setup-time only); numbers are
// parsed with std::from_chars so that the process locale can never change a file's
// meaning.
#include "formats/text_io.h"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

namespace mocap::formats_detail {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const noexcept {
    if (f) std::fclose(f);
  }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char ca = a[i];
    char cb = b[i];
    if (ca >= 'A' && ca <= 'Z') ca = static_cast<char>(ca - 'A' + 'a');
    if (cb >= 'A' && cb <= 'Z') cb = static_cast<char>(cb - 'A' + 'a');
    if (ca != cb) return false;
  }
  return true;
}

}  // namespace

void fail(const std::string& where, const std::string& what) { throw FieldError{where, what}; }

Expected<void> read_text_file(const std::string& path, std::string& out, std::size_t max_bytes) {
  errno = 0;
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) return make_error(path, "cannot open", std::strerror(errno));
  out.clear();
  std::array<char, 65536> buf{};
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f.get());
    out.append(buf.data(), n);
    if (n < buf.size()) break;
    // A link to /dev/zero or a runaway generator would otherwise grow `out` until the
    // process dies: no configuration or CSV of this tool comes near the bound.
    if (out.size() > max_bytes) {
      out.clear();
      return make_error(path, "cannot read",
                        "larger than " + std::to_string(max_bytes >> 20) + " MiB");
    }
  }
  if (std::ferror(f.get())) return make_error(path, "cannot read", std::strerror(errno));
  return {};
}

Expected<void> write_text_file(const std::string& path, std::string_view content) {
  errno = 0;
  FilePtr f(std::fopen(path.c_str(), "wb"));
  if (!f) return make_error(path, "cannot write", std::strerror(errno));
  if (std::fwrite(content.data(), 1, content.size(), f.get()) != content.size()) {
    return make_error(path, "cannot write", std::strerror(errno));
  }
  std::FILE* raw = f.release();
  if (std::fclose(raw) != 0) return make_error(path, "cannot write", std::strerror(errno));
  return {};
}

NumberStatus parse_double(std::string_view text, double& value) noexcept {
  std::string_view t = text;
  bool negative = false;
  if (!t.empty() && (t.front() == '+' || t.front() == '-')) {
    negative = t.front() == '-';
    t.remove_prefix(1);
  }
  if (iequals(t, ".nan") || iequals(t, "nan") || iequals(t, ".inf") || iequals(t, "inf") ||
      iequals(t, "infinity")) {
    const bool is_nan = iequals(t, ".nan") || iequals(t, "nan");
    value = is_nan ? std::nan("") : (negative ? -HUGE_VAL : HUGE_VAL);
    return NumberStatus::kNotFinite;
  }
  if (t.empty() || t.front() == '+' || t.front() == '-') return NumberStatus::kNotANumber;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || ptr != t.data() + t.size()) return NumberStatus::kNotANumber;
  value = negative ? -v : v;
  if (!std::isfinite(value)) return NumberStatus::kNotFinite;
  return NumberStatus::kOk;
}

NumberStatus parse_int64(std::string_view text, std::int64_t& value) noexcept {
  std::string_view t = text;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  if (t.empty()) return NumberStatus::kNotANumber;
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || ptr != t.data() + t.size()) return NumberStatus::kNotANumber;
  value = v;
  return NumberStatus::kOk;
}

void append_double(std::string& out, double value) {
  if (std::isnan(value)) {
    out += ".nan";
    return;
  }
  if (std::isinf(value)) {
    out += value > 0 ? ".inf" : "-.inf";
    return;
  }
  std::array<char, 64> buf{};
  const auto [ptr, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), value);
  (void)ec;  // 64 chars always suffice for the shortest representation of a double
  out.append(buf.data(), ptr);
}

std::string format_double(double value) {
  std::string s;
  append_double(s, value);
  return s;
}

std::string yaml_string(const std::string& s) {
  bool plain =
      !s.empty() && ((s[0] >= 'A' && s[0] <= 'Z') || (s[0] >= 'a' && s[0] <= 'z') || s[0] == '_');
  for (const char c : s) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) plain = false;
  }
  static constexpr std::array<const char*, 11> kReserved = {
      "true", "false", "yes", "no", "on", "off", "null", "y", "n", "nan", "inf"};
  for (const char* r : kReserved) {
    if (iequals(s, r)) plain = false;
  }
  if (plain) return s;
  std::string q = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      q += '\\';
      q += c;
    } else if (u < 0x20) {
      std::array<char, 8> hex{};
      std::snprintf(hex.data(), hex.size(), "\\x%02x", static_cast<unsigned>(u));
      q += hex.data();
    } else {
      q += c;
    }
  }
  q += '"';
  return q;
}

std::string name_problem(const std::string& name) {
  if (name.empty()) return "empty name";
  for (const char c : name) {
    if (c == ',' || c == '"' || c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20) {
      return "name '" + name +
             "' contains a character not allowed in names (, \" / \\ or a control character)";
    }
  }
  if (name.front() == ' ' || name.back() == ' ') {
    return "name '" + name + "' has leading or trailing spaces";
  }
  if (name == "." || name == "..") return "name '" + name + "' is not allowed";
  return {};
}

}  // namespace mocap::formats_detail
