// Design: the per-frame cost of the labelled-marker outputs of `mocap track`: building the
// labelled list (label_markers) and writing one frame to markers.csv (always written: the
// same-run baseline), to C3D and to TRC, for 3 bodies x 5 markers (the built-in scene has
// 5, 5, 4), all seen, and for a large 16 x 15 target set. Files go to /tmp (page cache), so this
// is the CPU cost of formatting and buffered writing, not of the disk. BM_FormatRow
// compares printf with the std::to_chars formatting the text writers use.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <memory>
#include <string>

#include "formats/c3d_writer.h"
#include "formats/fixed_text.h"
#include "formats/markers_csv.h"
#include "formats/trc_writer.h"
#include "track/labelled_markers.h"
#include "track/trajectory_export.h"

namespace {

using namespace mocap;

// `bodies` bodies of `markers` markers each, every marker identified.
struct Fixture {
  TargetSet targets;
  FrameOutput out;
  Fixture(int bodies, int markers) {
    out.points.set_capacity(bodies * markers);
    out.poses.count = bodies;
    for (int b = 0; b < bodies; ++b) {
      MarkerTarget t;
      t.name = "body" + std::to_string(b);
      BodyPose& pose = out.poses.bodies[static_cast<std::size_t>(b)];
      pose.found = true;
      pose.T_world_body.translation() = Vec3(100.0 * b, 20.0, 1500.0);
      pose.point_index_of_marker.fill(-1);
      for (int m = 0; m < markers; ++m) {
        t.markers_body.push_back(Vec3(10.0 * m, 3.0 * m, -2.0 * m));
        Point3 p;
        p.X_world = pose.T_world_body * t.markers_body.back() + Vec3(0.1, -0.05, 0.02);
        p.blob_index = {static_cast<std::int16_t>(m), static_cast<std::int16_t>(m), -1, -1};
        pose.point_index_of_marker[static_cast<std::size_t>(m)] =
            static_cast<std::int16_t>(out.points.size());
        out.points.push_back(p);
      }
      targets.bodies.push_back(t);
    }
  }
};

std::vector<FrameEntry> frames(int n) {
  std::vector<FrameEntry> f;
  for (int i = 0; i < n; ++i) f.push_back({i, 10'000'000LL * i});
  return f;
}

// kind 0: label_markers + markers.csv rows (baseline, always done); 1: + C3D; 2: + TRC.
void BM_LabelledFrame(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));
  const Fixture fx(static_cast<int>(state.range(1)), static_cast<int>(state.range(2)));
  const std::string dir = "/tmp/mocap_bench_exports_";
  LabelledExportPaths paths{dir + "markers.csv", kind == 1 ? dir + "x.c3d" : "",
                            kind == 2 ? dir + "x.trc" : ""};
  const std::vector<FrameEntry> f = frames(65535);
  auto exports = LabelledExports::open(paths, fx.targets, f, "frames.csv");
  if (!exports) {
    state.SkipWithError(exports.error().message.c_str());
    return;
  }
  auto labelled = std::make_unique<LabelledMarkers>();
  std::size_t i = 0;
  for (auto _ : state) {
    label_markers(fx.out, fx.targets, *labelled);
    exports->write_frame(i, *labelled);
    i = (i + 1) % f.size();
  }
  (void)exports->close();  // frame counts differ from the declared 65535: ignored here
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LabelledFrame)
    ->ArgNames({"kind", "bodies", "markers"})
    ->Args({0, 3, 5})
    ->Args({1, 3, 5})
    ->Args({2, 3, 5})
    ->Args({0, 16, 15})
    ->Args({1, 16, 15})
    ->Args({2, 16, 15});

// One markers.csv row into a buffer: printf's "%.6f" (kind 0, the same-run baseline, what
// the writers used before) vs std::to_chars (kind 1, what they use now). Same digits.
void BM_FormatRow(benchmark::State& state) {
  char buf[256];
  double x = 1234.567891, y = -87.654321, z = 15.0001, r = 0.012345;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      benchmark::DoNotOptimize(std::snprintf(buf, sizeof buf,
                                             "%lld,%lld,%s,%d,%.6f,%.6f,%.6f,%.6f\n", 1234LL,
                                             12340000000LL, "upper_arm", 3, x, y, z, r));
    } else {
      using namespace mocap::formats_detail;
      char* const end = buf + sizeof buf;
      char* p = put_int(buf, end, 1234);
      p = put_text(p, end, ",");
      p = put_int(p, end, 12340000000LL);
      p = put_text(p, end, ",upper_arm,");
      p = put_int(p, end, 3);
      for (double v : {x, y, z, r}) {
        p = put_text(p, end, ",");
        p = put_fixed(p, end, v, 6);
      }
      benchmark::DoNotOptimize(put_text(p, end, "\n"));
    }
    benchmark::ClobberMemory();
    x += 1e-6;  // new digits every row
  }
}
BENCHMARK(BM_FormatRow)->ArgName("to_chars")->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
