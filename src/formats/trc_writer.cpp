// Design: see trc_writer.h. Coordinates with 6 decimals (as markers.csv, both through
// std::to_chars: fixed_text.h), so a TRC value equals the markers.csv value exactly as text.
#include "formats/trc_writer.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "formats/fixed_text.h"

namespace mocap {

using namespace formats_detail;

namespace {

constexpr std::size_t kCellChars = 32;  // one 6-decimal cell of a coordinate + tab, bounded

}  // namespace

Expected<TrcWriter> TrcWriter::open(const std::string& path, const TrajectoryLayout& l) {
  if (l.labels.empty()) return make_error(path, "NumMarkers", "no markers to export");
  if (!(l.rate_hz > 0.0) || !std::isfinite(l.rate_hz))
    return make_error(path, "DataRate", "frame rate must be positive");
  for (const std::string& s : l.labels) {
    if (s.find_first_of("\t\r\n") != std::string::npos)
      return make_error(path, "markers", "label '" + s + "' contains a tab or line break");
  }
  auto file = ExportFile::open(path);
  if (!file) return file.error();
  TrcWriter w(std::move(file).value());
  std::string head =
      "PathFileType\t4\t(X/Y/Z)\t" + std::filesystem::path(path).filename().string() + "\n";
  head += "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\t";
  head += "OrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "%.6f\t%.6f\t%lld\t%zu\tmm\t%.6f\t%lld\t%lld\n", l.rate_hz,
                l.rate_hz, static_cast<long long>(l.frame_count), l.labels.size(), l.rate_hz,
                static_cast<long long>(l.first_frame), static_cast<long long>(l.frame_count));
  head += buf;
  head += "Frame#\tTime";
  for (const std::string& s : l.labels) head += "\t" + s + "\t\t";
  head += "\n\t";
  for (std::size_t i = 1; i <= l.labels.size(); ++i) {
    const std::string n = std::to_string(i);
    head += "\tX" + n + "\tY" + n + "\tZ" + n;
  }
  head += "\n\n";
  w.file_.write(head.data(), head.size());  // a failure is reported by close()
  w.markers_ = l.labels.size();
  w.line_.assign(64 + 3 * kCellChars * w.markers_, '\0');
  w.frames_declared_ = l.frame_count;
  return w;
}

bool TrcWriter::write_frame(std::int64_t frame_number, double time_s,
                            const TrajectorySample* samples) noexcept {
  if (file_.failed()) return false;
  char* const end = line_.data() + line_.size();
  char* p = put_int(line_.data(), end, frame_number);
  p = put_text(p, end, "\t");
  p = put_fixed(p, end, std::isfinite(time_s) ? time_s : 0.0, 6);
  for (std::size_t i = 0; i < markers_ && p; ++i) {
    const TrajectorySample& s = samples[i];
    if (!s.valid) {
      p = put_text(p, end, "\t\t\t");
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      // Coordinates beyond +-1e9 mm are not physical; clamp so the cell stays bounded.
      const double v = s.X_mm[k];
      p = put_text(p, end, "\t");
      p = put_fixed(p, end, std::isfinite(v) ? std::fmax(-1e9, std::fmin(1e9, v)) : 0.0, 6);
    }
  }
  p = put_text(p, end, "\n");
  if (!p) {
    file_.fail(EOVERFLOW);
    return false;
  }
  if (!file_.write(line_.data(), static_cast<std::size_t>(p - line_.data()))) return false;
  ++frames_written_;
  return true;
}

Expected<void> TrcWriter::close() {
  if (auto r = file_.close(); !r) return r;
  if (frames_written_ != frames_declared_) {
    return make_error(file_.path(), "NumFrames",
                      "wrote " + std::to_string(frames_written_) + " frames, declared " +
                          std::to_string(frames_declared_));
  }
  return {};
}

}  // namespace mocap
