// Design: the spec's markers.csv (extension 2026-12, "Labelled markers and exports"):
// `frame,timestamp_ns,body,marker,x,y,z,residual_mm`, one row per marker identified in a
// frame; `marker` is its index in targets.yaml, x,y,z the measured point in world mm,
// residual_mm its distance to the posed model marker. Streaming writer on CsvFile (write
// errors surface at close, naming the file) and a strict reader for tests and tools.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/csv_outputs.h"

namespace mocap {

struct MarkerRow {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::string body;
  int marker = 0;
  Vec3 X_world = Vec3::Zero();
  double residual_mm = 0.0;
};

Expected<CsvFile> open_markers_csv(const std::string& path);
// Writes one row; `body` is the body's name (not copied into a MarkerRow per row).
void write_marker_row(CsvFile& f, std::int64_t frame, std::int64_t timestamp_ns,
                      const std::string& body, int marker, const Vec3& X_world,
                      double residual_mm) noexcept;
Expected<std::vector<MarkerRow>> read_markers_csv(const std::string& path);

}  // namespace mocap
