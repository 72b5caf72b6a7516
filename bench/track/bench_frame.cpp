// Design: the markers-to-3D acceptance benchmark, all in one run on the same frame:
//  - ours: FrameProcessor::detect_camera for both cameras + StereoTriangulator::process
//    (undistortion, epipolar matching, niter2) on a simulator-rendered stereo frame;
//  - floor: one plain read of both images (sum of all pixels);
//  - OpenCV (when installed): cv::threshold + cv::connectedComponentsWithStats +
//    background-subtracted weighted centroids per component, cv::undistortPoints,
//    matching by epipolar distance (the same rule), cv::triangulatePoints.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <vector>

#include "sim/motion.h"
#include "sim/render.h"
#include "sim/simulate.h"
#include "track/frame_processor.h"

#ifdef MOCAP_BENCH_HAVE_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace mocap {
namespace {

struct Fixture {
  sim::SimScene scene;
  std::array<Image, 2> images;
  std::unique_ptr<FrameProcessor> proc;
  std::unique_ptr<StereoTriangulator> stereo;
};

Fixture& fixture() {
  static Fixture* f = [] {
    auto* fx = new Fixture();
    sim::SimOptions opt;
    auto scene = sim::make_scene(opt);
    if (!scene) std::abort();
    fx->scene = std::move(scene).value();
    auto ws = sim::RenderWorkspace::create(fx->scene);
    auto plan = sim::plan_motion(fx->scene, sim::MotionSpec{});
    if (!ws || !plan) std::abort();
    sim::SceneState state = sim::make_state(fx->scene);
    sim::apply_config(fx->scene, plan->configs[10], state);
    state.noise_key = sim::frame_noise_key(1, 10);
    for (int c = 0; c < 2; ++c) {
      fx->images[static_cast<std::size_t>(c)] = sim::make_camera_image(fx->scene, c);
      sim::render(fx->scene, state, c, *ws, fx->images[static_cast<std::size_t>(c)]);
    }
    auto proc = FrameProcessor::create(fx->scene.rig, fx->scene.targets, nullptr, TrackerConfig{});
    auto stereo = StereoTriangulator::create(fx->scene.rig, StereoConfig{});
    if (!proc || !stereo) std::abort();
    fx->proc = std::make_unique<FrameProcessor>(std::move(proc).value());
    fx->stereo = std::make_unique<StereoTriangulator>(std::move(stereo).value());
    return fx;
  }();
  return *f;
}

void BM_Ours_DetectAndTriangulate(benchmark::State& state) {
  Fixture& f = fixture();
  FrameOutput out = f.proc->make_output();
  std::array<std::vector<Vec2>, 2> px{std::vector<Vec2>(512), std::vector<Vec2>(512)};
  PointList points(1024);
  for (auto _ : state) {
    std::array<int, 2> n{};
    for (int c = 0; c < 2; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      f.proc->detect_camera(c, f.images[cs].view(), out.blobs[cs]);
      n[cs] = static_cast<int>(out.blobs[cs].size());
      for (int i = 0; i < n[cs]; ++i) {
        px[cs][static_cast<std::size_t>(i)] = Vec2(out.blobs[cs][static_cast<std::size_t>(i)].x_px,
                                                   out.blobs[cs][static_cast<std::size_t>(i)].y_px);
      }
    }
    f.stereo->process(px[0].data(), n[0], px[1].data(), n[1], points);
    benchmark::DoNotOptimize(points.size());
  }
  state.counters["points"] = points.size();
  state.counters["blobs0"] = static_cast<double>(out.blobs[0].size());
}
BENCHMARK(BM_Ours_DetectAndTriangulate)->Unit(benchmark::kMicrosecond);

// Stereo + identification + point selection on the detected blobs of the frame, with the
// whole-marker shape model (default) and with the blob flags alone (the baseline: the
// cost the physical shape test adds per frame).
void process_blobs_bench(benchmark::State& state, bool shape_model) {
  Fixture& f = fixture();
  TrackerConfig cfg;
  cfg.marker_shape.enabled = shape_model;
  auto proc = FrameProcessor::create(f.scene.rig, f.scene.targets, nullptr, cfg);
  if (!proc) std::abort();
  FrameOutput out = proc->make_output();
  for (int c = 0; c < 2; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    proc->detect_camera(c, f.images[cs].view(), out.blobs[cs]);
    out.camera_present[cs] = true;
  }
  std::int64_t t_ns = 0;
  for (auto _ : state) {
    t_ns += 10'000'000;
    proc->process_blobs(t_ns, out);
    benchmark::DoNotOptimize(out.poses.found);
  }
  state.counters["points"] = out.points.size();
  state.counters["bodies"] = out.poses.found;
}
void BM_ProcessBlobs_ShapeModel(benchmark::State& state) { process_blobs_bench(state, true); }
void BM_ProcessBlobs_FlagsOnly(benchmark::State& state) { process_blobs_bench(state, false); }
BENCHMARK(BM_ProcessBlobs_ShapeModel)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ProcessBlobs_FlagsOnly)->Unit(benchmark::kMicrosecond);

void BM_Floor_ReadBothImages(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    std::uint64_t sum = 0;
    for (const Image& img : f.images) {
      const std::uint8_t* p = img.data();
      for (std::size_t i = 0; i < img.size_bytes(); ++i) sum += p[i];
    }
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_Floor_ReadBothImages)->Unit(benchmark::kMicrosecond);

#ifdef MOCAP_BENCH_HAVE_OPENCV
void BM_OpenCV_DetectAndTriangulate(benchmark::State& state) {
  Fixture& f = fixture();
  std::array<cv::Mat, 2> K, D, P;
  for (std::size_t c = 0; c < 2; ++c) {
    const CameraModel& cam = f.scene.rig.cameras[c];
    K[c] = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    D[c] = cv::Mat(1, 5, CV_64F, const_cast<double*>(cam.distortion.data())).clone();
    P[c] = cv::Mat(3, 4, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) P[c].at<double>(r, k) = cam.R_cam_world(r, k);
      P[c].at<double>(r, 3) = cam.t_cam_world(r);
    }
  }
  const Mat3 R1 = f.scene.rig.cameras[1].R_cam_world * f.scene.rig.cameras[0].R_cam_world.transpose();
  const Vec3 t1 = f.scene.rig.cameras[1].t_cam_world - R1 * f.scene.rig.cameras[0].t_cam_world;
  Mat3 tx;
  tx << 0, -t1.z(), t1.y(), t1.z(), 0, -t1.x(), -t1.y(), t1.x(), 0;
  const Mat3 E = tx * R1;  // x1^T E x0 = 0 on normalised coordinates
  const double fx = f.scene.rig.cameras[0].fx;
  cv::Mat bin, labels, stats, cents;
  int points = 0;
  for (auto _ : state) {
    std::array<std::vector<cv::Point2d>, 2> undist;
    for (std::size_t c = 0; c < 2; ++c) {
      cv::Mat img(f.images[c].height(), f.images[c].width(), CV_8U, f.images[c].data());
      const double bg = 16.0;  // the background level is given, not estimated
      cv::threshold(img, bin, 40, 255, cv::THRESH_BINARY);
      const int n = cv::connectedComponentsWithStats(bin, labels, stats, cents, 8, CV_32S);
      std::vector<cv::Point2d> px;
      for (int l = 1; l < n; ++l) {
        const int x0 = stats.at<int>(l, cv::CC_STAT_LEFT), y0 = stats.at<int>(l, cv::CC_STAT_TOP);
        const int w = stats.at<int>(l, cv::CC_STAT_WIDTH), h = stats.at<int>(l, cv::CC_STAT_HEIGHT);
        double sw = 0, sx = 0, sy = 0;
        for (int y = y0; y < y0 + h; ++y) {
          for (int x = x0; x < x0 + w; ++x) {
            if (labels.at<int>(y, x) != l) continue;
            const double v = img.at<std::uint8_t>(y, x) - bg;
            sw += v;
            sx += v * x;
            sy += v * y;
          }
        }
        if (sw > 0) px.emplace_back(sx / sw, sy / sw);
      }
      if (!px.empty()) cv::undistortPoints(px, undist[c], K[c], D[c]);
    }
    std::vector<cv::Point2d> m0, m1;
    for (const auto& a : undist[0]) {
      for (const auto& b : undist[1]) {
        const Vec3 l = E * Vec3(a.x, a.y, 1.0);
        const double d = std::abs(l.dot(Vec3(b.x, b.y, 1.0))) / std::hypot(l.x(), l.y());
        if (d * fx < 2.0) {
          m0.push_back(a);
          m1.push_back(b);
        }
      }
    }
    cv::Mat X;
    if (!m0.empty()) cv::triangulatePoints(P[0], P[1], m0, m1, X);
    points = static_cast<int>(m0.size());
    benchmark::DoNotOptimize(X.data);
  }
  state.counters["points"] = points;
}
BENCHMARK(BM_OpenCV_DetectAndTriangulate)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
}  // namespace mocap

BENCHMARK_MAIN();
