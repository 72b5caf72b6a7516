// Design: small text helpers shared by the format readers and writers (internal to
// mocap_formats, not part of the public API): whole-file read/write with one-line
// "<file>: cannot open: <strerror>" errors, locale-independent number parsing that
// rejects trailing garbage, shortest round-trip double formatting (std::to_chars: the
// value read back is bit-identical), and YAML string quoting for names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "core/expected.h"

namespace mocap::formats_detail {

// A validation failure inside a loader: thrown by the field getters and converted to the
// one-line Error "<file>: <where>: <what>" at the public function's boundary (guard()).
struct FieldError {
  std::string where;  // key path or "line N", e.g. "cameras[1].R"
  std::string what;   // the problem, e.g. "expected 9 numbers, got 8 (line 12)"
};
[[noreturn]] void fail(const std::string& where, const std::string& what);

// Runs fn() (returning Expected<T>); converts a FieldError into an Error.
template <class T, class F>
Expected<T> guard_fields(const std::string& path, F&& fn) {
  try {
    return fn();
  } catch (const FieldError& e) {
    return make_error(path, e.where, e.what);
  }
}

// Reads the whole file into `out`. Error: "<path>: cannot open: <strerror>", or
// "<path>: cannot read: larger than N MiB" beyond max_bytes (a link to /dev/zero must end
// in an error, not in an out-of-memory kill). CSVs of long recordings fit the default;
// YAML files use kMaxYamlFileBytes.
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{1} << 30;
inline constexpr std::size_t kMaxYamlFileBytes = std::size_t{16} << 20;
Expected<void> read_text_file(const std::string& path, std::string& out,
                              std::size_t max_bytes = kMaxTextFileBytes);
// Writes (replaces) the file. Error: "<path>: cannot write: <strerror>".
Expected<void> write_text_file(const std::string& path, std::string_view content);

// Result of parsing a number: a value, or the reason it is not one.
enum class NumberStatus { kOk, kNotANumber, kNotFinite, kOutOfRange };

// Accepts decimal/scientific notation with an optional sign; YAML's .nan/.inf (any
// case, optional sign) and "nan"/"inf" are recognised and reported as kNotFinite.
NumberStatus parse_double(std::string_view text, double& value) noexcept;
// Accepts an optional sign and decimal digits only.
NumberStatus parse_int64(std::string_view text, std::int64_t& value) noexcept;

// Shortest decimal text that reads back as exactly `value` (".nan", ".inf", "-.inf" for
// non-finite values, YAML's spelling, which every reader rejects).
std::string format_double(double value);
void append_double(std::string& out, double value);

// A YAML scalar for a name: plain when it is a safe identifier, else double-quoted.
std::string yaml_string(const std::string& s);

// Problem with a body/joint/camera name that would break a CSV or a folder name, or
// an empty string when the name is fine.
std::string name_problem(const std::string& name);

}  // namespace mocap::formats_detail
