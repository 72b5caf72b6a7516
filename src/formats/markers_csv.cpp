// Design: see markers_csv.h. Same precision as points.csv (6 decimals, mm); rows are
// formatted with std::to_chars (fixed_text.h), the same digits as printf's %.6f.
#include "formats/markers_csv.h"

#include "formats/csv_parse.h"
#include "formats/fixed_text.h"
#include "formats/text_io.h"

namespace mocap {

using namespace formats_detail;

namespace {
constexpr const char* kMarkersHeader = "frame,timestamp_ns,body,marker,x,y,z,residual_mm";
}  // namespace

Expected<CsvFile> open_markers_csv(const std::string& path) {
  return CsvFile::open(path, kMarkersHeader);
}

void write_marker_row(CsvFile& f, std::int64_t frame, std::int64_t timestamp_ns,
                      const std::string& body, int marker, const Vec3& X_world,
                      double residual_mm) noexcept {
  if (!f.handle()) return;
  // As "%lld,%lld,%s,%d,%.6f,%.6f,%.6f,%.6f\n", formatted with to_chars (bench_exports).
  char buf[512];
  char* const end = buf + sizeof buf;
  char* p = put_int(buf, end, frame);
  p = put_text(p, end, ",");
  p = put_int(p, end, timestamp_ns);
  p = put_text(p, end, ",");
  p = put_text(p, end, body);
  p = put_text(p, end, ",");
  p = put_int(p, end, marker);
  for (double v : {X_world.x(), X_world.y(), X_world.z(), residual_mm}) {
    p = put_text(p, end, ",");
    p = put_fixed(p, end, v, 6);
  }
  p = put_text(p, end, "\n");
  if (p) {
    std::fwrite(buf, 1, static_cast<std::size_t>(p - buf), f.handle());
  } else {  // an absurdly long body name or number: the slow path still writes the row
    std::fprintf(f.handle(), "%lld,%lld,%s,%d,%.6f,%.6f,%.6f,%.6f\n", static_cast<long long>(frame),
                 static_cast<long long>(timestamp_ns), body.c_str(), marker, X_world.x(),
                 X_world.y(), X_world.z(), residual_mm);
  }
}

Expected<std::vector<MarkerRow>> read_markers_csv(const std::string& path) {
  auto reader = CsvReader::open(path, kMarkersHeader);
  if (!reader) return reader.error();
  return guard_fields<std::vector<MarkerRow>>(path, [&]() -> Expected<std::vector<MarkerRow>> {
    std::vector<MarkerRow> rows;
    CsvReader& r = *reader;
    while (r.next()) {
      MarkerRow m;
      m.frame = r.integer(0);
      m.timestamp_ns = r.integer(1);
      m.body = std::string(r.text(2));
      const std::int64_t marker = r.integer(3);
      if (marker < 0 || marker > 1000000) fail(r.where(), "column 'marker': out of range");
      m.marker = static_cast<int>(marker);
      m.X_world = Vec3(r.number(4), r.number(5), r.number(6));
      m.residual_mm = r.number(7);
      rows.push_back(std::move(m));
    }
    return rows;
  });
}

}  // namespace mocap
