// Benchmarks of the stereo stage on the paper's rig (1032x776, f ~ 1290 px, 477 mm
// baseline, verged at 1 m), 0.3 px noise on the blobs:
//  - triangulation per point: niter2 vs linear DLT (both from normalised undistorted
//    coordinates), and the full pixel -> 3D path (undistort both + niter2) vs OpenCV's
//    cv::undistortPoints + cv::triangulatePoints on the same points (batch of 1024);
//  - correspondence + triangulation of whole frames with 15, 50 and 200 markers per
//    camera, sorted sweep vs exhaustive n*m search.
// With OpenCV, BM_ProjectVsOpenCV also reports the largest difference between our
// project() and cv::projectPoints (counter max_diff_px), a bench-only cross-check.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "stereo/stereo_triangulator.h"
#include "stereo/two_view.h"
#include "tests/stereo/stereo_test_rig.h"

#ifdef MOCAP_BENCH_HAVE_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace mocap {
namespace {

constexpr int kBatch = 1024;

struct Observations {
  Rig rig;
  std::vector<Vec2> px0, px1, xn0, xn1;
};

const Observations& observations() {
  static const Observations obs = [] {
    Observations o;
    o.rig = test::paper_rig();
    std::mt19937 rng(42);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (int i = 0; i < kBatch; ++i) {
      Vec2 a, b, xa, xb;
      test::random_visible_point(o.rig, rng, a, b);
      a += Vec2(noise(rng), noise(rng));
      b += Vec2(noise(rng), noise(rng));
      undistort_pixel(o.rig.cameras[0], a, xa);
      undistort_pixel(o.rig.cameras[1], b, xb);
      o.px0.push_back(a);
      o.px1.push_back(b);
      o.xn0.push_back(xa);
      o.xn1.push_back(xb);
    }
    return o;
  }();
  return obs;
}

void BM_TriangulateNiter2(benchmark::State& state) {
  const Observations& o = observations();
  const StereoGeometry g = make_stereo_geometry(o.rig.cameras[0], o.rig.cameras[1]).value();
  for (auto _ : state) {
    for (int i = 0; i < kBatch; ++i) {
      Vec3 X;
      benchmark::DoNotOptimize(triangulate_niter2(g, o.xn0[i], o.xn1[i], X));
      benchmark::DoNotOptimize(X);
    }
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_TriangulateNiter2);

void BM_TriangulateDlt(benchmark::State& state) {
  const Observations& o = observations();
  const StereoGeometry g = make_stereo_geometry(o.rig.cameras[0], o.rig.cameras[1]).value();
  for (auto _ : state) {
    for (int i = 0; i < kBatch; ++i) {
      Vec3 X;
      benchmark::DoNotOptimize(triangulate_dlt(g, o.xn0[i], o.xn1[i], X));
      benchmark::DoNotOptimize(X);
    }
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_TriangulateDlt);

// Pixel -> 3D: undistort both blobs, niter2, world point (what OpenCV's pair below does).
void BM_PixelsToPointNiter2(benchmark::State& state) {
  const Observations& o = observations();
  const auto& c0 = o.rig.cameras[0];
  const auto& c1 = o.rig.cameras[1];
  const StereoGeometry g = make_stereo_geometry(c0, c1).value();
  for (auto _ : state) {
    for (int i = 0; i < kBatch; ++i) {
      Vec2 xa, xb;
      Vec3 X;
      undistort_pixel(c0, o.px0[i], xa);
      undistort_pixel(c1, o.px1[i], xb);
      benchmark::DoNotOptimize(triangulate_niter2(g, xa, xb, X));
      benchmark::DoNotOptimize(X);
    }
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_PixelsToPointNiter2);

#ifdef MOCAP_BENCH_HAVE_OPENCV
cv::Mat camera_matrix(const CameraModel& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat dist_coeffs(const CameraModel& c) {
  return (cv::Mat_<double>(1, 5) << c.distortion[0], c.distortion[1], c.distortion[2],
          c.distortion[3], c.distortion[4]);
}
cv::Mat projection_matrix(const CameraModel& c) {
  cv::Mat P(3, 4, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) P.at<double>(r, k) = c.R_cam_world(r, k);
    P.at<double>(r, 3) = c.t_cam_world[r];
  }
  return P;
}

void BM_PixelsToPointOpenCV(benchmark::State& state) {
  const Observations& o = observations();
  const auto& c0 = o.rig.cameras[0];
  const auto& c1 = o.rig.cameras[1];
  std::vector<cv::Point2d> p0, p1;
  for (int i = 0; i < kBatch; ++i) {
    p0.emplace_back(o.px0[i].x(), o.px0[i].y());
    p1.emplace_back(o.px1[i].x(), o.px1[i].y());
  }
  const cv::Mat K0 = camera_matrix(c0), K1 = camera_matrix(c1);
  const cv::Mat D0 = dist_coeffs(c0), D1 = dist_coeffs(c1);
  const cv::Mat P0 = projection_matrix(c0), P1 = projection_matrix(c1);
  // cv::undistortPoints' default 5 fixed-point iterations are not enough at the image
  // border; give it a converging criterion as a fair baseline.
  const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-12);
  double worst_mm = 0.0;
  for (auto _ : state) {
    std::vector<cv::Point2d> n0, n1;
    cv::undistortPoints(p0, n0, K0, D0, cv::noArray(), cv::noArray(), crit);
    cv::undistortPoints(p1, n1, K1, D1, cv::noArray(), cv::noArray(), crit);
    cv::Mat X4;
    cv::triangulatePoints(P0, P1, n0, n1, X4);
    benchmark::DoNotOptimize(X4.data);
    state.PauseTiming();
    const StereoGeometry g = make_stereo_geometry(c0, c1).value();
    for (int i = 0; i < kBatch; i += 64) {  // agreement with our DLT, as a sanity check
      const double w = X4.at<double>(3, i);
      const Vec3 Xcv(X4.at<double>(0, i) / w, X4.at<double>(1, i) / w, X4.at<double>(2, i) / w);
      Vec3 Xd;
      if (triangulate_dlt(g, o.xn0[i], o.xn1[i], Xd))
        worst_mm = std::max(worst_mm, (Xd - Xcv).norm());
    }
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["max_diff_vs_our_dlt_mm"] = worst_mm;
}
BENCHMARK(BM_PixelsToPointOpenCV);

void BM_ProjectVsOpenCV(benchmark::State& state) {
  const Observations& o = observations();
  double worst = 0.0;
  for (auto _ : state) {
    for (int k = 0; k < 2; ++k) {
      const CameraModel& c = o.rig.cameras[static_cast<std::size_t>(k)];
      std::mt19937 rng(7);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      std::vector<cv::Point3d> X;
      std::vector<Vec3> Xe;
      for (int i = 0; i < 1000; ++i) {
        const Vec3 Xi(450 * u(rng), 350 * u(rng), 1000 + 400 * u(rng));
        X.emplace_back(Xi.x(), Xi.y(), Xi.z());
        Xe.push_back(Xi);
      }
      cv::Mat R(3, 3, CV_64F), rvec;
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) R.at<double>(r, q) = c.R_cam_world(r, q);
      cv::Rodrigues(R, rvec);
      const cv::Mat tvec =
          (cv::Mat_<double>(3, 1) << c.t_cam_world.x(), c.t_cam_world.y(), c.t_cam_world.z());
      std::vector<cv::Point2d> px;
      cv::projectPoints(X, rvec, tvec, camera_matrix(c), dist_coeffs(c), px);
      for (int i = 0; i < 1000; ++i) {
        Vec2 p;
        if (project(c, Xe[i], p)) worst = std::max(worst, (p - Vec2(px[i].x, px[i].y)).norm());
      }
    }
  }
  state.counters["max_diff_px"] = worst;
}
BENCHMARK(BM_ProjectVsOpenCV)->Iterations(1);
#endif

// Whole frames: n markers per camera (camera 1 shuffled), correspondence + niter2.
void BM_Correspondence(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto method = state.range(1) == 0 ? MatchMethod::kSortedSweep : MatchMethod::kExhaustive;
  const Rig rig = test::paper_rig();
  StereoConfig cfg;
  cfg.method = method;
  auto st = StereoTriangulator::create(rig, cfg).value();
  std::mt19937 rng(static_cast<unsigned>(n));
  std::normal_distribution<double> noise(0.0, 0.3);
  constexpr int kFrames = 16;
  std::vector<std::vector<Vec2>> fa(kFrames), fb(kFrames);
  for (int f = 0; f < kFrames; ++f) {
    for (int i = 0; i < n; ++i) {
      Vec2 a, b;
      test::random_visible_point(rig, rng, a, b);
      fa[f].push_back(a + Vec2(noise(rng), noise(rng)));
      fb[f].push_back(b + Vec2(noise(rng), noise(rng)));
    }
    std::shuffle(fb[f].begin(), fb[f].end(), rng);
  }
  PointList out(cfg.max_candidates);
  std::int64_t candidates = 0;
  int f = 0;
  for (auto _ : state) {
    st.process(fa[f].data(), n, fb[f].data(), n, out);
    candidates += out.size();
    f = (f + 1) % kFrames;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["candidates_per_frame"] =
      static_cast<double>(candidates) / static_cast<double>(state.iterations());
  state.SetLabel(method == MatchMethod::kSortedSweep ? "sweep" : "exhaustive");
}
BENCHMARK(BM_Correspondence)
    ->ArgsProduct({{15, 50, 200}, {0, 1}})
    ->ArgNames({"n", "exhaustive"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mocap

BENCHMARK_MAIN();
