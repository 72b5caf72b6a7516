// Design: measures reading one camera frame (1032x776, the spec's example size) from a
// PGM file into a reused Image, 8-bit and 16-bit, as replay does per frame, against
// OpenCV's cv::imread of the same file (baseline; it allocates a new Mat per call).
// The file stays in the page cache, so this is the CPU cost of the reader itself.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "formats/pgm.h"
#include "formats/recording.h"

#ifdef MOCAP_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

namespace {

constexpr int kWidth = 1032;
constexpr int kHeight = 776;

std::string make_file(bool wide) {
  const std::string path = std::string("/tmp/mocap_bench_pgm_") + (wide ? "16" : "8") + ".pgm";
  mocap::Image img(kWidth, kHeight, wide ? mocap::PixelFormat::kMono16 : mocap::PixelFormat::kMono8,
                   wide ? 4095 : 255);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (wide) {
        img.row16(y)[x] = static_cast<std::uint16_t>((x * 3 + y * 5) & 4095);
      } else {
        img.row8(y)[x] = static_cast<std::uint8_t>((x + y) & 255);
      }
    }
  }
  if (!mocap::write_pgm(path, img.view()).ok()) std::abort();
  return path;
}

void BM_ReadPgm(benchmark::State& state) {
  const bool wide = state.range(0) == 16;
  const std::string path = make_file(wide);
  mocap::Image img;
  for (auto _ : state) {
    const bool ok = mocap::read_pgm_expect(path, kWidth, kHeight, img).ok();
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(img.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(img.size_bytes()));
  std::remove(path.c_str());
}
BENCHMARK(BM_ReadPgm)->Arg(8)->Arg(16);

#ifdef MOCAP_HAVE_OPENCV
void BM_OpenCvImread(benchmark::State& state) {
  const bool wide = state.range(0) == 16;
  const std::string path = make_file(wide);
  std::size_t bytes = 0;
  for (auto _ : state) {
    cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
    benchmark::DoNotOptimize(m.data);
    bytes = m.total() * m.elemSize();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
  std::remove(path.c_str());
}
BENCHMARK(BM_OpenCvImread)->Arg(8)->Arg(16);
#endif

}  // namespace

BENCHMARK_MAIN();
