// Design: see csv_parse.h.
#include "formats/csv_parse.h"

#include "formats/text_io.h"

namespace mocap::formats_detail {
namespace {

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out.push_back(line.substr(start));
      return out;
    }
    out.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
}

std::string_view take_line(const std::string& s, std::size_t& pos) {
  const std::size_t end = s.find('\n', pos);
  std::string_view line(s.data() + pos, (end == std::string::npos ? s.size() : end) - pos);
  pos = end == std::string::npos ? s.size() : end + 1;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

}  // namespace

Expected<CsvReader> CsvReader::open(const std::string& path, const char* columns) {
  CsvReader r;
  if (auto ok = read_text_file(path, r.content_); !ok) return ok.error();
  for (const std::string_view c : split(columns)) r.columns_.emplace_back(c);
  if (r.content_.empty()) {
    return make_error(path, "", std::string("empty file (expected the header '") + columns + "')");
  }
  const std::string_view header = take_line(r.content_, r.pos_);
  r.line_no_ = 1;
  const std::vector<std::string_view> names = split(header);
  bool ok = names.size() >= r.columns_.size();
  for (std::size_t i = 0; ok && i < r.columns_.size(); ++i) ok = names[i] == r.columns_[i];
  if (!ok) {
    std::string shown(header.substr(0, 120));
    return make_error(path, "line 1",
                      "header '" + shown + "' does not start with '" + columns + "'");
  }
  return r;
}

bool CsvReader::next() {
  while (pos_ < content_.size()) {
    const std::string_view line = take_line(content_, pos_);
    ++line_no_;
    if (line.empty()) continue;
    fields_ = split(line);
    if (fields_.size() < columns_.size()) {
      fail(where(), "expected " + std::to_string(columns_.size()) + " fields, got " +
                        std::to_string(fields_.size()));
    }
    return true;
  }
  return false;
}

std::string CsvReader::column_name(std::size_t column) const {
  return column < columns_.size() ? columns_[column] : std::to_string(column + 1);
}

std::string_view CsvReader::text(std::size_t column) const {
  const std::string_view f = fields_[column];
  if (f.empty())
    fail(where(), "column '" +
                      column_name(column) +
                      "': empty field");
  return f;
}

double CsvReader::number(std::size_t column) const {
  const std::string_view f = text(column);
  double v = 0.0;
  switch (parse_double(f, v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kNotFinite:
      fail(where(),
           "column '" + column_name(column) + "': not a finite number: '" + std::string(f) + "'");
    case NumberStatus::kOutOfRange:
      fail(where(),
           "column '" + column_name(column) + "': number out of range: '" + std::string(f) + "'");
    case NumberStatus::kNotANumber:
      break;
  }
  fail(where(),
       "column '" + column_name(column) + "': expected a number, got '" + std::string(f) + "'");
}

std::int64_t CsvReader::integer(std::size_t column) const {
  const std::string_view f = text(column);
  std::int64_t v = 0;
  switch (parse_int64(f, v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kOutOfRange:
      fail(where(),
           "column '" + column_name(column) + "': integer out of range: '" + std::string(f) + "'");
    default:
      break;
  }
  fail(where(),
       "column '" + column_name(column) + "': expected an integer, got '" + std::string(f) + "'");
}

}  // namespace mocap::formats_detail
