// `mocap run [--udp HOST:PORT] [--duration SECONDS] [--stats FILE] [--rate HZ]
// [--loop-frames N] [--no-realtime] [--no-iceoryx]`: the live tracker (pipeline/). With no
// configuration it runs on the simulated stereo pair of the built-in scenario (a
// pre-rendered loop, hal/sim_camera.h) with the simulator's true joint model, and
// publishes every frame over UDP (127.0.0.1:7755 by default) and iceoryx, through the
// publishers of pipeline/publish when they are built in (MOCAP_HAVE_PUBLISH). --duration, SIGINT or
// SIGTERM stop it cleanly (the signal handler only sets an atomic flag); it then prints the latency
// statistics and, with --stats, writes them as JSON.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/command_registry.h"
#include "hal/sim_camera.h"
#include "pipeline/pipeline.h"
#include "pipeline/stats_report.h"
#ifdef MOCAP_HAVE_PUBLISH
#include "pipeline/publish/publishers.h"
#endif

namespace mocap::app {
namespace {

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "used from a signal handler");

extern "C" void on_stop_signal(int) {
  // relaxed: a lock-free atomic store is async-signal-safe; the main loop polls it.
  g_stop_requested.store(true, std::memory_order_relaxed);
}

#ifdef MOCAP_HAVE_PUBLISH
// The UDP + iceoryx publishers of pipeline/publish as a pipeline sink.
class PublishersSink final : public pipeline::JointsSink {
 public:
  explicit PublishersSink(publish::Publishers p) : p_(std::move(p)) {}
  bool publish(const client::JointsMessage& m) noexcept override { return p_.publish(m); }
  const publish::Publishers& publishers() const noexcept { return p_; }

 private:
  publish::Publishers p_;
};
#endif

struct RunArgs {
  std::string udp = "127.0.0.1:7755";
  double duration_s = 0.0;  // 0: until SIGINT/SIGTERM
  std::string stats;
  double rate_hz = 100.0;
  int loop_frames = 200;
  bool no_realtime = false;
  bool no_iceoryx = false;
};

// "HOST:PORT" with a port in 1..65535 (the UDP publisher resolves the host).
Expected<std::pair<std::string, int>> parse_host_port(const std::string& s) {
  const std::size_t colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == s.size())
    return make_error("--udp", s, "expected HOST:PORT");
  int port = 0;
  for (std::size_t i = colon + 1; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9' || port > 65535) return make_error("--udp", s, "bad port");
    port = port * 10 + (s[i] - '0');
  }
  if (port < 1 || port > 65535) return make_error("--udp", s, "port must be in 1..65535");
  return std::make_pair(s.substr(0, colon), port);
}

int run_live(const RunArgs& a) {
  auto udp = parse_host_port(a.udp);
  if (!udp) return fail(udp.error().message);
  if (a.duration_s < 0.0) return fail("--duration: must be >= 0");

  std::fprintf(stderr,
               "mocap run: rendering the simulated camera loop (%d frames x 2 cameras)...\n",
               a.loop_frames);
  sim::SimOptions so;
  so.frames = a.loop_frames;
  so.fps = a.rate_hz;
  auto loop = hal::SimFrameLoop::render(so);
  if (!loop) return fail(loop.error().message);
  std::fprintf(stderr, "mocap run: simulated loop ready (%.0f MB)\n",
               static_cast<double>((*loop)->memory_bytes()) / 1e6);
  auto trigger = std::make_shared<hal::SimTrigger>(*loop);
  std::unique_ptr<hal::SimCamera> cams[2];
  pipeline::PipelineOptions opt;
  opt.trigger_rate_hz = a.rate_hz;
  opt.realtime = !a.no_realtime;
  if (a.duration_s > 0.0) {
    opt.latency_capacity = static_cast<std::size_t>(a.duration_s * a.rate_hz * 1.2) + 1024;
  }
  if (opt.latency_capacity > (std::size_t{1} << 23)) opt.latency_capacity = std::size_t{1} << 23;
  for (int c = 0; c < 2; ++c) {
    auto cam = hal::SimCamera::open(trigger, c);
    if (!cam) return fail(cam.error().message);
    cams[c] = std::move(cam).value();
    hal::CameraConfig cfg = cams[c]->native_config();
    cfg.buffer_count = static_cast<int>(
        opt.stages[pipeline::index(pipeline::StageId::kDetect0) + static_cast<std::size_t>(c)]
            .ring_depth +
        3);
    if (auto r = cams[c]->configure(cfg); !r) return fail(r.error().message);
  }
  const sim::SimScene& scene = (*loop)->scene();
  auto proc = FrameProcessor::create(scene.rig, scene.targets, &scene.joints_true, TrackerConfig{});
  if (!proc) return fail(proc.error().message);

  // Sinks: the publishers of pipeline/publish plug in here.
  std::vector<std::unique_ptr<pipeline::JointsSink>> owned_sinks;
  std::vector<pipeline::JointsSink*> sinks;
#ifdef MOCAP_HAVE_PUBLISH
  publish::PublishersConfig pc;
  pc.udp_destinations = {a.udp};
  pc.iceoryx = !a.no_iceoryx;
  auto pubs = publish::Publishers::create(pc);
  if (!pubs) return fail(pubs.error().message);
  if (!pubs->notice().empty())
    std::fprintf(stderr, "mocap run: note: %s\n", pubs->notice().c_str());
  owned_sinks.push_back(std::make_unique<PublishersSink>(std::move(pubs).value()));
#else
  std::fprintf(stderr,
               "mocap run: note: the publishers (pipeline/publish) are not built in: "
               "joint angles for %s:%d are computed but not sent\n",
               udp->first.c_str(), udp->second);
#endif
  for (auto& s : owned_sinks) sinks.push_back(s.get());

  auto pipe = pipeline::Pipeline::create(std::move(proc).value(), {cams[0].get(), cams[1].get()},
                                         sinks, opt);
  if (!pipe) return fail(pipe.error().message);

  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  if (auto r = (*pipe)->start(); !r) return fail(r.error().message);
  for (const std::string& n : (*pipe)->notes())
    std::fprintf(stderr, "mocap run: note: %s\n", n.c_str());
  if (a.duration_s > 0.0) {
    std::fprintf(stderr, "mocap run: running at %.0f Hz for %.1f s (Ctrl-C stops)\n", a.rate_hz,
                 a.duration_s);
  } else {
    std::fprintf(stderr, "mocap run: running at %.0f Hz (Ctrl-C stops)\n", a.rate_hz);
  }
  const auto t0 = std::chrono::steady_clock::now();
  while (!g_stop_requested.load(std::memory_order_relaxed)) {
    if (a.duration_s > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >=
            a.duration_s)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  (*pipe)->stop();
  const pipeline::PipelineStats st = (*pipe)->stats();
  std::fputs(pipeline::format_pipeline_stats(st).c_str(), stdout);
  if (!a.stats.empty()) {
    if (auto r = pipeline::write_pipeline_stats_json(a.stats, st); !r)
      return fail(r.error().message);
  }
  return 0;
}

void register_run(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run the live tracker (default: simulated cameras of the built-in scenario)");
  cmd->add_option("--udp", args->udp, "Send joint angles to HOST:PORT (default 127.0.0.1:7755)");
  cmd->add_option("--duration", args->duration_s,
                  "Stop after this many seconds (default: until Ctrl-C)");
  cmd->add_option("--stats", args->stats, "Write latency statistics to this JSON file at the end");
  cmd->add_option("--rate", args->rate_hz,
                  "Trigger rate of the simulated cameras in Hz (default 100)")
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_option("--loop-frames", args->loop_frames,
                  "Frames pre-rendered for the simulated cameras (default 200: 320 MB)")
      ->check(CLI::Range(2, 2000));
  cmd->add_flag("--no-realtime", args->no_realtime, "No CPU pinning and no SCHED_FIFO");
  cmd->add_flag("--no-iceoryx", args->no_iceoryx, "Do not publish over iceoryx shared memory");
  cmd->callback([args, &exit_code] { exit_code = run_live(*args); });
}

const CommandRegistrar kRegistrar(60, register_run);

}  // namespace
}  // namespace mocap::app
