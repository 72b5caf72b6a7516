// Design: the soak benchmark of issue 8 (not a CI test: it runs for tens of minutes).
// Pushes many simulated stereo frames (default one million) through the tracker and
// reports, per window of frames, the frame latency (p50/p99/max), the resident memory
// and the heap allocations of the processing thread, so that growth in memory or
// latency over the run shows as a trend between the first and the last windows.
//   processor mode (default): FrameProcessor::process() on one thread, frames replayed
//     from a pre-rendered simulator loop (ping-pong, so the motion stays continuous);
//     the latency is the call's wall time.
//   pipeline mode (--pipeline): the live pipeline (five threads, simulated cameras,
//     lockstep pacing as fast as it goes); the latency is from the frame's latency origin
//     (hal::latency_origin_ns, the same start as the pipeline's statistics: the trigger
//     of a live or simulated camera, a replay's delivery) to identify done, recorded by a
//     FrameObserver + FrameTap into memory allocated before start.
// Processor mode also reports the p99 of the thread's CPU time per frame, which the
// preemption by other processes on a shared machine does not inflate.
// RSS comes from /proc/self/statm, read between windows (processor mode) or once a
// second by the main thread (pipeline mode): never inside the measured work.
// Usage: bench_soak [--frames N] [--window W] [--loop L] [--pipeline] [--csv FILE]
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "hal/sim_camera.h"
#include "pipeline/pipeline.h"
#include "tests/support/alloc_counter.h"
#include "track/frame_processor.h"

namespace {

using namespace mocap;

struct Args {
  std::uint64_t frames = 1'000'000;
  std::uint64_t window = 50'000;
  int loop = 40;
  bool pipeline = false;
  std::string csv;
};

double rss_mib() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return -1.0;
  long size = 0, resident = 0;
  const int n = std::fscanf(f, "%ld %ld", &size, &resident);
  std::fclose(f);
  if (n != 2) return -1.0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) /
         (1024.0 * 1024.0);
}

struct WindowRow {
  std::uint64_t first_frame = 0, frames = 0;
  double p50_us = 0, p99_us = 0, max_us = 0, rss_mib = 0;
  double cpu_p99_us = -1;  // processor mode: the thread's CPU time (immune to preemption)
  std::uint64_t allocations = 0, all_found = 0;
};

WindowRow summarize(std::vector<std::int64_t>& ns, std::uint64_t first, double rss) {
  WindowRow w;
  w.first_frame = first;
  w.frames = ns.size();
  if (ns.empty()) return w;
  std::sort(ns.begin(), ns.end());
  auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(q * static_cast<double>(ns.size() - 1) + 0.5);
    return static_cast<double>(ns[i]) * 1e-3;
  };
  w.p50_us = at(0.50);
  w.p99_us = at(0.99);
  w.max_us = static_cast<double>(ns.back()) * 1e-3;
  w.rss_mib = rss;
  return w;
}

void print_rows(const std::vector<WindowRow>& rows, const Args& a, const char* mode) {
  std::printf("%-10s %8s %10s %10s %10s %11s %9s %8s %9s\n", "first", "frames", "p50_us", "p99_us",
              "max_us", "cpu_p99_us", "rss_MiB", "allocs", "found_%");
  for (const WindowRow& w : rows) {
    std::printf(
        "%-10llu %8llu %10.1f %10.1f %10.1f %11.1f %9.1f %8llu %9.1f\n",
        static_cast<unsigned long long>(w.first_frame), static_cast<unsigned long long>(w.frames),
        w.p50_us, w.p99_us, w.max_us, w.cpu_p99_us, w.rss_mib,
        static_cast<unsigned long long>(w.allocations),
        w.frames ? 100.0 * static_cast<double>(w.all_found) / static_cast<double>(w.frames) : 0.0);
  }
  if (rows.size() >= 2) {
    const WindowRow& f = rows[1];  // the first window after warm-up
    const WindowRow& l = rows.back();
    double p99_max = 0;
    for (std::size_t i = 1; i < rows.size(); ++i) p99_max = std::max(p99_max, rows[i].p99_us);
    std::printf(
        "%s: windows 2..%zu: RSS %.1f -> %.1f MiB (%+.2f MiB), p99 %.1f -> %.1f us (worst window "
        "%.1f us)\n",
        mode, rows.size(), f.rss_mib, l.rss_mib, l.rss_mib - f.rss_mib, f.p99_us, l.p99_us,
        p99_max);
  }
  if (!a.csv.empty()) {
    if (std::FILE* out = std::fopen(a.csv.c_str(), "w")) {
      std::fprintf(
          out,
          "first_frame,frames,p50_us,p99_us,max_us,cpu_p99_us,rss_mib,allocations,all_found\n");
      for (const WindowRow& w : rows)
        std::fprintf(out, "%llu,%llu,%.2f,%.2f,%.2f,%.2f,%.2f,%llu,%llu\n",
                     static_cast<unsigned long long>(w.first_frame),
                     static_cast<unsigned long long>(w.frames), w.p50_us, w.p99_us, w.max_us,
                     w.cpu_p99_us, w.rss_mib, static_cast<unsigned long long>(w.allocations),
                     static_cast<unsigned long long>(w.all_found));
      std::fclose(out);
    }
  }
}

// The calling thread's CPU time (a syscall, ~0.2 us: small next to a frame).
std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

bool all_found(const FrameOutput& out) {
  for (int b = 0; b < out.poses.count; ++b)
    if (!out.poses.bodies[static_cast<std::size_t>(b)].found) return false;
  return out.poses.count > 0;
}

int run_processor(const Args& a, const hal::SimFrameLoop& loop) {
  const sim::SimScene& sc = loop.scene();
  auto proc = FrameProcessor::create(sc.rig, sc.targets, &sc.joints_true, TrackerConfig{});
  if (!proc) {
    std::fprintf(stderr, "bench_soak: %s\n", proc.error().message.c_str());
    return 2;
  }
  FrameOutput out = proc->make_output();
  std::vector<std::int64_t> ns, cpu_ns;
  ns.reserve(a.window);
  cpu_ns.reserve(a.window);
  std::vector<WindowRow> rows;
  const auto period_ns = static_cast<std::int64_t>(1e9 / loop.fps());
  for (std::uint64_t first = 0; first < a.frames; first += a.window) {
    const std::uint64_t end = std::min(a.frames, first + a.window);
    ns.clear();
    cpu_ns.clear();
    std::uint64_t found = 0;
    const test::AllocationScope allocs;
    for (std::uint64_t i = first; i < end; ++i) {
      const int f = loop.frame_of_sequence(i);
      const ImageView v0 = loop.image(f, 0).view(), v1 = loop.image(f, 1).view();
      const std::int64_t c0 = thread_cpu_ns();
      const auto t0 = std::chrono::steady_clock::now();
      proc->process(std::array<const ImageView*, 2>{&v0, &v1},
                    static_cast<std::int64_t>(i) * period_ns, out);
      const auto t1 = std::chrono::steady_clock::now();
      cpu_ns.push_back(thread_cpu_ns() - c0);
      ns.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
      found += all_found(out) ? 1 : 0;
    }
    const std::uint64_t n_alloc = allocs.count();
    WindowRow w = summarize(ns, first, rss_mib());
    w.cpu_p99_us = summarize(cpu_ns, first, 0.0).p99_us;
    w.allocations = n_alloc;
    w.all_found = found;
    rows.push_back(w);
    std::fprintf(stderr, "\rbench_soak: %llu / %llu frames", static_cast<unsigned long long>(end),
                 static_cast<unsigned long long>(a.frames));
  }
  std::fprintf(stderr, "\n");
  print_rows(rows, a, "processor");
  return 0;
}

// Pipeline mode: each frame's latency from where the pipeline's own statistics start
// (hal::latency_origin_ns of camera 0's frame: a live or simulated camera's trigger, a
// replay's delivery; the published capture_ns may be a recording's time instead) to
// identify done. The tap (capture thread) notes the origin per sequence number before
// the frame goes to its detector; the observer (identify thread) reads it once that
// frame's blobs arrived, so the rings between the stages order the two accesses
// (relaxed atomics: no further ordering is needed, and TSan sees no plain race).
class LatencyObserver final : public pipeline::FrameObserver, public pipeline::FrameTap {
 public:
  explicit LatencyObserver(std::size_t n) : origin_ns_(n), ns_(n, 0), found_(n, 0) {}
  void on_frame(int camera, const hal::Frame& frame) noexcept override {
    if (camera != 0 || frame.sequence >= origin_ns_.size()) return;
    origin_ns_[frame.sequence].store(hal::latency_origin_ns(frame), std::memory_order_relaxed);
  }
  void observe(std::uint64_t sequence, std::int64_t capture_ns,
               const FrameOutput& out) noexcept override {
    if (sequence >= ns_.size()) return;
    const std::int64_t origin = origin_ns_[sequence].load(std::memory_order_relaxed);
    ns_[sequence] = hal::monotonic_ns() - (origin != 0 ? origin : capture_ns);
    found_[sequence] = all_found(out) ? 1 : 0;
  }
  std::vector<std::atomic<std::int64_t>> origin_ns_;  // by sequence; 0: not seen
  std::vector<std::int64_t> ns_;
  std::vector<std::uint8_t> found_;
};

class CountingSink final : public publish::OutputSink {
 public:
  const char* name() const noexcept override { return "counting"; }
  publish::OutputCounters counters() const noexcept override { return {}; }
  bool publish(const publish::FrameResult&) noexcept override { return true; }
};

int run_pipeline(const Args& a, const std::shared_ptr<const hal::SimFrameLoop>& loop) {
  auto trig = std::make_shared<hal::SimTrigger>(loop);
  std::unique_ptr<hal::SimCamera> cams[2];
  for (int c = 0; c < 2; ++c) {
    auto cam = hal::SimCamera::open(trig, c);
    hal::CameraConfig cfg;
    if (cam) {
      cfg = (*cam)->native_config();
      cfg.buffer_count = 8;  // the pipeline holds ring depth + 2 buffers per camera
    }
    if (!cam || !(*cam)->configure(cfg)) {
      std::fprintf(stderr, "bench_soak: cannot open the simulated cameras\n");
      return 2;
    }
    cams[c] = std::move(cam).value();
  }
  const sim::SimScene& sc = loop->scene();
  auto proc = FrameProcessor::create(sc.rig, sc.targets, &sc.joints_true, TrackerConfig{});
  if (!proc) return 2;
  LatencyObserver obs(a.frames);
  CountingSink sink;
  pipeline::PipelineOptions opt;
  opt.realtime = false;
  opt.lock_memory = false;
  opt.pacing = pipeline::TriggerPacing::kLockstep;
  opt.trigger_rate_hz = 5000.0;
  opt.max_frames = a.frames;
  opt.observer = &obs;
  opt.tap = &obs;  // the latency origin of each frame, as the pipeline's statistics use it
  auto p = pipeline::Pipeline::create(std::move(proc).value(), {cams[0].get(), cams[1].get()},
                                      {&sink}, opt);
  if (!p) {
    std::fprintf(stderr, "bench_soak: %s\n", p.error().message.c_str());
    return 2;
  }
  if (auto s = (*p)->start(); !s) {
    std::fprintf(stderr, "bench_soak: %s\n", s.error().message.c_str());
    return 2;
  }
  std::vector<std::pair<std::uint64_t, double>> rss;  // (frames published, MiB)
  while (!(*p)->finished()) {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    rss.emplace_back((*p)->frames_published(), rss_mib());
    std::fprintf(stderr, "\rbench_soak: %llu / %llu frames",
                 static_cast<unsigned long long>(rss.back().first),
                 static_cast<unsigned long long>(a.frames));
  }
  (*p)->stop();
  std::fprintf(stderr, "\n");
  std::vector<WindowRow> rows;
  std::vector<std::int64_t> ns;
  for (std::uint64_t first = 0; first < a.frames; first += a.window) {
    const std::uint64_t end = std::min(a.frames, first + a.window);
    ns.clear();
    std::uint64_t found = 0;
    for (std::uint64_t i = first; i < end; ++i) {
      if (obs.ns_[i] > 0) ns.push_back(obs.ns_[i]);
      found += obs.found_[i];
    }
    double r = rss.empty() ? -1.0 : rss.back().second;  // the first sample once the window was done
    for (const auto& [n, mib] : rss) {
      if (n >= end) {
        r = mib;
        break;
      }
    }
    WindowRow w = summarize(ns, first, r);
    w.all_found = found;
    rows.push_back(w);
  }
  print_rows(rows, a, "pipeline");
  const pipeline::PipelineStats st = (*p)->stats();
  std::printf("pipeline: %llu triggered, %llu published in %.1f s\n",
              static_cast<unsigned long long>(st.triggered),
              static_cast<unsigned long long>(st.published), st.duration_s);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : ""; };
    if (k == "--frames")
      a.frames = std::strtoull(next(), nullptr, 10);
    else if (k == "--window")
      a.window = std::strtoull(next(), nullptr, 10);
    else if (k == "--loop")
      a.loop = std::atoi(next());
    else if (k == "--pipeline")
      a.pipeline = true;
    else if (k == "--csv")
      a.csv = next();
    else {
      std::fprintf(
          stderr,
          "usage: bench_soak [--frames N] [--window W] [--loop L] [--pipeline] [--csv FILE]\n");
      return 2;
    }
  }
  if (a.frames == 0 || a.window == 0 || a.loop < 2) {
    std::fprintf(stderr, "bench_soak: --frames and --window must be >= 1, --loop >= 2\n");
    return 2;
  }
  sim::SimOptions o;
  o.frames = a.loop;
  auto loop = hal::SimFrameLoop::render(o);
  if (!loop) {
    std::fprintf(stderr, "bench_soak: %s\n", loop.error().message.c_str());
    return 2;
  }
  std::printf(
      "bench_soak: %llu frames, windows of %llu, loop of %d rendered frames (%.0f MiB), mode %s\n",
      static_cast<unsigned long long>(a.frames), static_cast<unsigned long long>(a.window), a.loop,
      static_cast<double>((*loop)->memory_bytes()) / (1024.0 * 1024.0),
      a.pipeline ? "pipeline" : "processor");
  return a.pipeline ? run_pipeline(a, *loop) : run_processor(a, **loop);
}
