// Design: a small strict CSV line reader for the spec's CSV files (internal to
// mocap_formats): the whole file is read at once, the header must start with the
// spec's columns (extra columns at the end are allowed and ignored, as the spec lets
// writers add them), '\r\n' line ends are accepted, empty lines are skipped, and field
// getters throw FieldError{"line N", "column 'x': ..."} (convert with guard_fields).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/expected.h"

namespace mocap::formats_detail {

class CsvReader {
 public:
  // Reads `path` and checks its header against `columns` (comma-separated).
  static Expected<CsvReader> open(const std::string& path, const char* columns);

  // Advances to the next non-empty data line; false at the end of the file.
  // Throws FieldError when the line has fewer fields than the header's columns.
  bool next();
  std::size_t line_number() const noexcept { return line_no_; }
  std::string where() const { return "line " + std::to_string(line_no_); }

  // Whether the current row has this column (extension columns beyond the header's).
  bool has_column(std::size_t column) const noexcept { return column < fields_.size(); }
  // Whether the current row's field is empty (an optional value left out); the column exists.
  bool field_empty(std::size_t column) const noexcept { return fields_[column].empty(); }
  std::string_view text(std::size_t column) const;  // non-empty
  double number(std::size_t column) const;          // finite
  std::int64_t integer(std::size_t column) const;

 private:
  std::string content_;
  std::vector<std::string> columns_;
  std::vector<std::string_view> fields_;
  // The header's name of a column, or its 1-based number beyond the header.
  std::string column_name(std::size_t column) const;
  std::size_t pos_ = 0;
  std::size_t line_no_ = 0;
};

}  // namespace mocap::formats_detail
