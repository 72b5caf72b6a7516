// Design: Google Benchmark of the blob detector. Scenes: synthetic markers (diameter
// 6-14 px, background 20 DN, amplitude 180-230 DN, noise 2 DN; x257 in 16 bits) in
// 640x480, 1032x776, 1280x1024 and 2048x1536 images with 10, 50 and 200 markers.
// For each scene three timings: our detector (adaptive threshold, default config);
// two floors (one plain read of the image: the sum of all pixels in a simple loop,
// and a memcpy of the image); and, when OpenCV is
// found, the baseline a user would otherwise write: cv::threshold (cv::compare for
// 16-bit) + cv::connectedComponentsWithStats + background-subtracted intensity-weighted
// centroids per component over its bounding box. The stereo-frame case (2 x 1032x776,
// 15 markers each) is the acceptance scene. Args: {width, height, markers, bits}.
// BM_DetectScan compares the two scan strategies in one run on a tracking-like scene
// (1280x1024 8-bit, 60 markers of 5-7 px diameter, tracker config): full_scan 0 = the
// default two-pass scan, 1 = the reference full scan; images 1 = the same image every
// iteration (cache-hot, as after a file read), 16 = cycling through 16 images (21 MB:
// every detect reads its image from L3/DRAM, as in the live pipeline).
#include <benchmark/benchmark.h>

#include <cstring>
#include <map>
#include <memory>
#include <tuple>
#include <vector>

#include "detect/blob_detector.h"
#include "tests/detect/synth.h"

#if MOCAP_BENCH_HAVE_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace {

using mocap::ImageView;
using mocap::PixelFormat;
using namespace mocap::detect;
using mocap::detect::test::SynthImage;
using mocap::detect::test::SynthParams;

struct Scene {
  SynthImage image;
  int threshold_dn;
  int background_dn;
};

const Scene& scene(int w, int h, int markers, int bits, std::uint32_t seed = 1) {
  static std::map<std::tuple<int, int, int, int, std::uint32_t>, std::unique_ptr<Scene>> cache;
  auto& slot = cache[{w, h, markers, bits, seed}];
  if (!slot) {
    SynthParams p;
    p.width = w;
    p.height = h;
    p.format = bits == 8 ? PixelFormat::kMono8 : PixelFormat::kMono16;
    p.maxval = bits == 8 ? 255 : 65535;
    const double scale = bits == 8 ? 1.0 : 257.0;
    p.background_dn = 20 * scale;
    p.noise_sigma_dn = 2 * scale;
    p.seed = seed;
    const auto spots = mocap::detect::test::random_discs(markers, p, 3.0, 7.0, 180 * scale,
                                                         230 * scale, 3.0, seed + 100);
    slot =
        std::make_unique<Scene>(Scene{mocap::detect::test::render(spots, p),
                                      static_cast<int>(32 * scale), static_cast<int>(20 * scale)});
  }
  return *slot;
}

DetectorConfig bench_config(int bits) {
  DetectorConfig cfg;
  cfg.min_contrast_dn = bits == 8 ? 12 : 12 * 257;
  return cfg;
}

void set_counters(benchmark::State& state, const ImageView& v) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * v.height * v.width *
                          bytes_per_pixel(v.format));
}

void BM_Detect(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const int bits = static_cast<int>(state.range(3));
  const Scene& s = scene(w, h, static_cast<int>(state.range(2)), bits);
  auto det = BlobDetector::create(bench_config(bits), w, h);
  BlobList blobs = det->make_blob_list();
  for (auto _ : state) {
    det->detect(s.image.view, blobs);
    benchmark::DoNotOptimize(blobs.begin());
  }
  state.counters["blobs"] = static_cast<double>(blobs.size());
  set_counters(state, s.image.view);
}

const SynthImage& tracking_scene(int w, int h, int markers, std::uint32_t seed) {
  static std::map<std::tuple<int, int, int, std::uint32_t>, std::unique_ptr<SynthImage>> cache;
  auto& slot = cache[{w, h, markers, seed}];
  if (!slot) {
    SynthParams p;
    p.width = w;
    p.height = h;
    p.background_dn = 12;
    p.noise_sigma_dn = 2;
    p.blur_sigma_px = 0.5;
    p.seed = seed;
    const auto spots =
        mocap::detect::test::random_discs(markers, p, 2.5, 3.5, 120, 230, 3.0, seed + 100);
    slot = std::make_unique<SynthImage>(mocap::detect::test::render(spots, p));
  }
  return *slot;
}

void BM_DetectScan(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const int markers = static_cast<int>(state.range(2));
  const int images = static_cast<int>(state.range(4));
  std::vector<ImageView> views;
  for (int i = 0; i < images; ++i) {
    views.push_back(tracking_scene(w, h, markers, static_cast<std::uint32_t>(1 + i)).view);
  }
  DetectorConfig cfg = bench_config(8);
  cfg.max_elongation = 1.3;  // as TrackerConfig
  cfg.full_scan = state.range(3) != 0;
  auto det = BlobDetector::create(cfg, w, h);
  BlobList blobs = det->make_blob_list();
  std::size_t k = 0;
  for (auto _ : state) {
    det->detect(views[k], blobs);
    k = k + 1 == views.size() ? 0 : k + 1;
    benchmark::DoNotOptimize(blobs.begin());
  }
  state.counters["blobs"] = static_cast<double>(blobs.size());
  set_counters(state, views[0]);
}

// The floor: one plain read of every pixel.
void BM_ReadFloor(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const int bits = static_cast<int>(state.range(3));
  const ImageView v = scene(w, h, static_cast<int>(state.range(2)), bits).image.view;
  for (auto _ : state) {
    std::uint64_t sum = 0;
    for (int y = 0; y < v.height; ++y) {
      if (bits == 8) {
        const std::uint8_t* r = v.row8(y);
        for (int x = 0; x < v.width; ++x) sum += r[x];
      } else {
        const std::uint16_t* r = v.row16(y);
        for (int x = 0; x < v.width; ++x) sum += r[x];
      }
    }
    benchmark::DoNotOptimize(sum);
  }
  set_counters(state, v);
}

// A second floor: memcpy of the image into a buffer allocated at setup.
void BM_MemcpyFloor(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const int bits = static_cast<int>(state.range(3));
  const ImageView v = scene(w, h, static_cast<int>(state.range(2)), bits).image.view;
  const std::size_t bytes =
      static_cast<std::size_t>(v.stride_bytes) * static_cast<std::size_t>(v.height);
  std::vector<std::uint8_t> dst(bytes);
  for (auto _ : state) {
    std::memcpy(dst.data(), v.data, bytes);
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, v);
}

#if MOCAP_BENCH_HAVE_OPENCV
struct CvWorkspace {
  cv::Mat mask, labels, stats, centroids;
};

// What a user would write with OpenCV; returns the number of centroids.
int opencv_detect(const ImageView& v, int threshold_dn, int background_dn, CvWorkspace& ws,
                  double* xs, double* ys, int cap) {
  const int type = v.format == PixelFormat::kMono8 ? CV_8UC1 : CV_16UC1;
  const cv::Mat img(v.height, v.width, type, const_cast<std::uint8_t*>(v.data),
                    static_cast<std::size_t>(v.stride_bytes));
  if (type == CV_8UC1) {
    cv::threshold(img, ws.mask, threshold_dn - 1, 255, cv::THRESH_BINARY);
  } else {
    cv::compare(img, threshold_dn, ws.mask, cv::CMP_GE);
  }
  const int n =
      cv::connectedComponentsWithStats(ws.mask, ws.labels, ws.stats, ws.centroids, 8, CV_32S);
  int out = 0;
  for (int i = 1; i < n && out < cap; ++i) {
    const int x0 = ws.stats.at<int>(i, cv::CC_STAT_LEFT), y0 = ws.stats.at<int>(i, cv::CC_STAT_TOP);
    const int bw = ws.stats.at<int>(i, cv::CC_STAT_WIDTH),
              bh = ws.stats.at<int>(i, cv::CC_STAT_HEIGHT);
    if (ws.stats.at<int>(i, cv::CC_STAT_AREA) < 4) continue;
    double sw = 0, sx = 0, sy = 0;
    for (int y = y0; y < y0 + bh; ++y) {
      const int* lab = ws.labels.ptr<int>(y);
      for (int x = x0; x < x0 + bw; ++x) {
        if (lab[x] != i) continue;
        const double p = type == CV_8UC1 ? img.at<std::uint8_t>(y, x) : img.at<std::uint16_t>(y, x);
        const double wgt = p - background_dn;
        sw += wgt;
        sx += wgt * x;
        sy += wgt * y;
      }
    }
    xs[out] = sx / sw;
    ys[out] = sy / sw;
    ++out;
  }
  return out;
}

void BM_OpenCV(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const int bits = static_cast<int>(state.range(3));
  const Scene& s = scene(w, h, static_cast<int>(state.range(2)), bits);
  CvWorkspace ws;
  double xs[512], ys[512];
  int n = 0;
  for (auto _ : state) {
    n = opencv_detect(s.image.view, s.threshold_dn, s.background_dn, ws, xs, ys, 512);
    benchmark::DoNotOptimize(xs);
  }
  state.counters["blobs"] = n;
  set_counters(state, s.image.view);
}
#endif

// Acceptance scene: both images of a stereo frame (2 x 1032x776, ~15 markers each).
void BM_StereoFrameDetect(benchmark::State& state) {
  const int bits = static_cast<int>(state.range(0));
  const Scene& a = scene(1032, 776, 15, bits, 1);
  const Scene& b = scene(1032, 776, 15, bits, 2);
  auto da = BlobDetector::create(bench_config(bits), 1032, 776);
  auto db = BlobDetector::create(bench_config(bits), 1032, 776);
  BlobList la = da->make_blob_list(), lb = db->make_blob_list();
  for (auto _ : state) {
    da->detect(a.image.view, la);
    db->detect(b.image.view, lb);
    benchmark::DoNotOptimize(la.begin());
    benchmark::DoNotOptimize(lb.begin());
  }
  state.counters["blobs"] = static_cast<double>(la.size() + lb.size());
}

#if MOCAP_BENCH_HAVE_OPENCV
void BM_StereoFrameOpenCV(benchmark::State& state) {
  const int bits = static_cast<int>(state.range(0));
  const Scene& a = scene(1032, 776, 15, bits, 1);
  const Scene& b = scene(1032, 776, 15, bits, 2);
  CvWorkspace ws;
  double xs[512], ys[512];
  int n = 0;
  for (auto _ : state) {
    n = opencv_detect(a.image.view, a.threshold_dn, a.background_dn, ws, xs, ys, 512);
    n += opencv_detect(b.image.view, b.threshold_dn, b.background_dn, ws, xs, ys, 512);
    benchmark::DoNotOptimize(xs);
  }
  state.counters["blobs"] = n;
}
#endif

void BM_StereoFrameReadFloor(benchmark::State& state) {
  const int bits = static_cast<int>(state.range(0));
  const ImageView va = scene(1032, 776, 15, bits, 1).image.view;
  const ImageView vb = scene(1032, 776, 15, bits, 2).image.view;
  for (auto _ : state) {
    std::uint64_t sum = 0;
    for (const ImageView& v : {va, vb}) {
      for (int y = 0; y < v.height; ++y) {
        if (bits == 8) {
          const std::uint8_t* r = v.row8(y);
          for (int x = 0; x < v.width; ++x) sum += r[x];
        } else {
          const std::uint16_t* r = v.row16(y);
          for (int x = 0; x < v.width; ++x) sum += r[x];
        }
      }
    }
    benchmark::DoNotOptimize(sum);
  }
}

void BM_StereoFrameMemcpyFloor(benchmark::State& state) {
  const int bits = static_cast<int>(state.range(0));
  const ImageView va = scene(1032, 776, 15, bits, 1).image.view;
  const ImageView vb = scene(1032, 776, 15, bits, 2).image.view;
  const std::size_t bytes =
      static_cast<std::size_t>(va.stride_bytes) * static_cast<std::size_t>(va.height);
  std::vector<std::uint8_t> dst(2 * bytes);
  for (auto _ : state) {
    std::memcpy(dst.data(), va.data, bytes);
    std::memcpy(dst.data() + bytes, vb.data, bytes);
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
}

void scene_args(benchmark::internal::Benchmark* b) {
  for (int bits : {8, 16}) {
    for (auto [w, h] : {std::pair{640, 480}, {1032, 776}, {1280, 1024}, {2048, 1536}}) {
      for (int markers : {10, 50, 200}) b->Args({w, h, markers, bits});
    }
  }
  b->ArgNames({"w", "h", "markers", "bits"})->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Detect)->Apply(scene_args);
BENCHMARK(BM_DetectScan)
    ->ArgsProduct({{1280}, {1024}, {60}, {0, 1}, {1, 16}})
    ->ArgNames({"w", "h", "markers", "full_scan", "images"})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ReadFloor)->Apply(scene_args);
BENCHMARK(BM_MemcpyFloor)->Apply(scene_args);
#if MOCAP_BENCH_HAVE_OPENCV
BENCHMARK(BM_OpenCV)->Apply(scene_args);
BENCHMARK(BM_StereoFrameOpenCV)->Arg(8)->Arg(16)->ArgName("bits")->Unit(benchmark::kMicrosecond);
#endif
BENCHMARK(BM_StereoFrameDetect)->Arg(8)->Arg(16)->ArgName("bits")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StereoFrameReadFloor)->Arg(8)->Arg(16)->ArgName("bits")->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_StereoFrameMemcpyFloor)
    ->Arg(8)
    ->Arg(16)
    ->ArgName("bits")
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
