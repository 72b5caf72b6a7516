// Design: setup-time error handling in the style of iceoryx's `expected`.
// Functions that run before start() (loading files, validating configuration,
// allocating workspaces) return Expected<T>: either a value or an Error whose
// message is ONE line naming the file, the key or line, and the problem, e.g.
//   "rig.yaml: cameras[1].R: not a rotation (det = -1.000)".
// Hot-path code never uses this type; it returns bool/status codes and counts
// failures (see DEVELOPERS.md, real-time rules).
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace mocap {

struct Error {
  std::string message;
};

// "file: where: what" (where may be empty -> "file: what"). Always ONE line: control
// characters that reach a message from a damaged input (e.g. a YAML scalar or a parser
// message quoting the offending byte) are written as "\xNN".
inline Error make_error(const std::string& file, const std::string& where,
                        const std::string& what) {
  std::string m = where.empty() ? file + ": " + what : file + ": " + where + ": " + what;
  for (std::size_t i = 0; i < m.size(); ++i) {
    const auto c = static_cast<unsigned char>(m[i]);
    if (c >= 0x20 && c != 0x7F) continue;
    static constexpr char kHex[] = "0123456789abcdef";
    const char esc[4] = {'\\', 'x', kHex[c >> 4], kHex[c & 0xF]};
    m.replace(i, 1, esc, 4);
    i += 3;
  }
  return Error{std::move(m)};
}

template <class T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}       // NOLINT: implicit by design
  Expected(Error error) : v_(std::move(error)) {}   // NOLINT: implicit by design

  bool ok() const noexcept { return v_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T* operator->() { return &std::get<0>(v_); }
  const T* operator->() const { return &std::get<0>(v_); }
  T& operator*() & { return std::get<0>(v_); }
  const T& operator*() const& { return std::get<0>(v_); }

  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

template <>
class [[nodiscard]] Expected<void> {
 public:
  Expected() = default;
  Expected(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT: implicit
  bool ok() const noexcept { return ok_; }
  explicit operator bool() const noexcept { return ok_; }
  const Error& error() const { return error_; }

 private:
  Error error_{};
  bool ok_ = true;
};

}  // namespace mocap
