// `mocap run [--udp HOST:PORT] [--multicast-if ADDR] [--multicast-ttl N] [--duration SECONDS]
// [--stats FILE] [--stats-interval S] [--rate HZ] [--loop-frames N] [--no-realtime]
// [--no-iceoryx] [--ros2] [--foxglove [ADDR:]PORT] [--vrpn [ADDR:]PORT]`: the live tracker
// (pipeline/). With no configuration it runs on the simulated stereo pair of the built-in
// scenario (a pre-rendered loop, hal/sim_camera.h) with the simulator's true joint model, and
// publishes every frame over UDP (127.0.0.1:7755 by default) and iceoryx, through the
// outputs of the registry (pipeline/publish/output_registry.h; --ros2, --foxglove, --vrpn).
// --duration, SIGINT or
// SIGTERM stop it cleanly (the signal handler only sets an atomic flag); it then prints the latency
// statistics and, with --stats, writes them as JSON. While running, every --stats-interval
// seconds one progress line goes to stderr (pipeline::format_progress_line); at the end a
// warning line per camera whose images overflowed the detector or whose clock stepped.
// --config FILE runs the cameras, tracker, stage table and outputs of a configuration
// file (docs/operations.md; flags given on the command line override it);
// --check-config FILE only validates one. Under systemd (NOTIFY_SOCKET) the supervisor of
// pipeline/service sends READY, WATCHDOG (only while frames progress) and STATUS.
// Structure: parse (RunArgs) -> service::resolve_run_config -> service::LiveSetup (cameras,
// tracker, options) -> publish::create_outputs -> Pipeline::create/start -> supervise (periodic
// report, sd_notify, stop conditions) -> report.
#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/command_registry.h"
#include "app/config_flags.h"
#include "hal/camera.h"
#include "pipeline/pipeline.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/service/live_setup.h"
#include "pipeline/service/notifier.h"
#include "pipeline/service/supervisor.h"
#include "pipeline/stats_report.h"

namespace mocap::app {
namespace {

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "used from a signal handler");

// Who sent the stop signal: iox-roudi SIGTERMs every registered client when it shuts down.
std::atomic<int> g_stop_sender_pid{0};
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");

extern "C" void on_stop_signal(int, siginfo_t* info, void*) {
  // relaxed: lock-free atomic stores are async-signal-safe; the main loop polls the flag
  // and reads the pid only after it stopped (same thread as the handler: no race).
  g_stop_sender_pid.store(info != nullptr ? static_cast<int>(info->si_pid) : 0,
                          std::memory_order_relaxed);
  g_stop_requested.store(true, std::memory_order_relaxed);
}

// True when process `pid` is iox-roudi (/proc/PID/comm).
bool is_roudi(int pid) {
  if (pid <= 0) return false;
  std::FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/comm").c_str(), "r");
  if (f == nullptr) return false;
  char comm[32] = {};
  const bool ok = std::fgets(comm, sizeof comm, f) != nullptr;
  std::fclose(f);
  return ok && std::string(comm).rfind("iox-roudi", 0) == 0;
}

// Exit code when iox-roudi's shutdown stopped the tracker (EX_TEMPFAIL): a systemd unit
// with Restart=on-failure brings the tracker back, on UDP only while RouDi is away.
constexpr int kExitRouDiShutdown = 75;

struct RunArgs {
  // The configuration's overrides (--udp, --multicast-*, --rate, --loop-frames,
  // --no-realtime, --no-iceoryx): no defaults here, checked by resolve_run_config.
  service::CliOverrides cli;
  double duration_s = 0.0;  // 0: until SIGINT/SIGTERM
  std::string stats;
  double stats_interval_s = 5.0;  // 0: no periodic report
  bool ros2 = false;              // --ros2
  std::string foxglove;           // --foxglove [ADDR:]PORT
  std::string vrpn;               // --vrpn [ADDR:]PORT
  std::string config;             // --config FILE
  std::string check_config;       // --check-config FILE
};

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_sigaction = on_stop_signal;
  sa.sa_flags = SA_SIGINFO;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// Runs until --duration, SIGINT/SIGTERM; prints a progress line every --stats-interval.
void supervise(const pipeline::Pipeline& pipe, const RunArgs& a, service::Supervisor& service) {
  const auto t0 = std::chrono::steady_clock::now();
  auto seconds_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  auto last_report = t0;
  LatencySnapshot last_e2e = pipe.end_to_end()->snapshot();
  while (!g_stop_requested.load(std::memory_order_relaxed)) {
    if (a.duration_s > 0.0 && seconds_since(t0) >= a.duration_s) break;
    if (pipe.finished()) {  // a replayed recording was played to its end
      std::fprintf(stderr, "mocap run: the recording ended\n");
      break;
    }
    service.poll(hal::monotonic_ns());  // sd_notify READY / WATCHDOG / STATUS
    if (a.stats_interval_s > 0.0 && seconds_since(last_report) >= a.stats_interval_s) {
      const double interval_s = seconds_since(last_report);
      last_report = std::chrono::steady_clock::now();
      LatencySnapshot e2e = pipe.end_to_end()->snapshot();
      const std::string line = pipeline::format_progress_line(
          seconds_since(t0), interval_s, e2e.since(last_e2e).stats(), pipe.health());
      std::fprintf(stderr, "mocap run: %s\n", line.c_str());
      last_e2e = std::move(e2e);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// One warning line per camera whose images overflowed the detector or whose clock
// stepped (the counters say how often; docs/pipeline.md).
void report_camera_faults(const pipeline::PipelineHealth& h) {
  for (int c = 0; c < h.camera_count; ++c) {
    const auto i = static_cast<std::size_t>(c);
    if (h.detect_overflow_frames[i] > 0)
      std::fprintf(stderr,
                   "mocap run: warning: camera %d: %llu frames overflowed the detector's run "
                   "or blob capacity (detect_cam%d_frames_overflow)\n",
                   c, static_cast<unsigned long long>(h.detect_overflow_frames[i]), c);
    if (h.timestamp_steps[i] > 0)
      std::fprintf(stderr,
                   "mocap run: warning: camera %d: its clock stepped %llu times "
                   "(timestamp_backwards_cam%d, timestamp_jumps_cam%d)\n",
                   c, static_cast<unsigned long long>(h.timestamp_steps[i]), c, c);
  }
}

int run_live(const RunArgs& a) {
  if (a.duration_s < 0.0) return fail("--duration: must be >= 0");
  if (a.stats_interval_s < 0.0) return fail("--stats-interval: must be >= 0");

  // The configuration (--config FILE, else the built-in sim defaults) with the flags given
  // on top; cameras, tracker and stage table from it (pipeline/service/live_setup.h).
  service::CliOverrides cli = a.cli;
  if (a.ros2) cli.outputs.emplace_back("ros2", "true");
  if (!a.foxglove.empty()) cli.outputs.emplace_back("foxglove", a.foxglove);
  if (!a.vrpn.empty()) cli.outputs.emplace_back("vrpn", a.vrpn);
  auto cfg = service::resolve_run_config(a.config, cli);
  if (!cfg) return fail(cfg.error().message);
  // Handlers first: a SIGTERM while the sim loop renders (seconds) must still stop cleanly.
  install_stop_handlers();
  auto live = service::LiveSetup::create(*cfg, stderr);
  if (!live) return fail(live.error().message);
  for (const std::string& n : (*live)->notices())
    std::fprintf(stderr, "mocap run: note: %s\n", n.c_str());
  const pipeline::PipelineOptions opt = (*live)->options();
  // Every output from the one registry (outputs: of the configuration + the flags).
  FrameProcessor processor = (*live)->take_processor();
  publish::OutputContext context;  // pointers used only while the outputs are created
  context.targets = &processor.targets();
  context.model = processor.has_model() ? &processor.model() : nullptr;
  context.rig = &processor.rig();
  context.frame_rate_hz = opt.trigger_rate_hz;
  auto outputs = publish::create_outputs(service::output_requests(*cfg, cli), context);
  if (!outputs) return fail(outputs.error().message);
  for (const std::string& n : outputs->notices)
    std::fprintf(stderr, "mocap run: note: %s\n", n.c_str());
  auto pipe =
      pipeline::Pipeline::create(std::move(processor), (*live)->cameras(), outputs->list(), opt);
  if (!pipe) return fail(pipe.error().message);

  if (g_stop_requested.load(std::memory_order_relaxed)) {
    std::fprintf(stderr, "mocap run: stopped before start\n");
    return 0;
  }
  if (auto r = (*pipe)->start(); !r) return fail(r.error().message);
  for (const std::string& n : (*pipe)->notes())
    std::fprintf(stderr, "mocap run: note: %s\n", n.c_str());
  if (a.duration_s > 0.0) {
    std::fprintf(stderr, "mocap run: running at %.0f Hz for %.1f s (Ctrl-C stops)\n",
                 opt.trigger_rate_hz, a.duration_s);
  } else {
    std::fprintf(stderr, "mocap run: running at %.0f Hz (Ctrl-C stops)\n", opt.trigger_rate_hz);
  }
  service::SdNotifier notifier;
  service::SupervisorOptions so;
  so.status_interval_s = cfg->service.status_interval_s;
  so.log_interval_s = cfg->service.log_interval_s;
  service::Supervisor service(**pipe, notifier, so);  // the pipeline's one health view
  supervise(**pipe, a, service);
  service.stopping();
  (*pipe)->stop();
  pipeline::PipelineStats st = (*pipe)->stats();
  (*live)->add_node_stats(st);  // camera nodes: legs, counters, clock offsets
  std::fputs(pipeline::format_pipeline_stats(st).c_str(), stdout);
  std::fputs((*live)->node_report().c_str(), stdout);  // camera nodes: empty without
  report_camera_faults((*pipe)->health());
  if (!a.stats.empty()) {
    if (auto r = pipeline::write_pipeline_stats_json(a.stats, st); !r)
      return fail(r.error().message);
  }
  if (g_stop_requested.load(std::memory_order_relaxed) &&
      is_roudi(g_stop_sender_pid.load(std::memory_order_relaxed))) {
    // iceoryx 2.0 cannot deregister a running process: RouDi SIGKILLs every client that
    // outlives its SIGTERM by --kill-delay (45 s), so stop cleanly now (docs/pipeline.md).
    std::fprintf(stderr,
                 "mocap run: iceoryx: RouDi (iox-roudi) shut down and sent SIGTERM: stopped "
                 "(exit %d); restart to continue over UDP only\n",
                 kExitRouDiShutdown);
    return kExitRouDiShutdown;
  }
  return 0;
}

void register_run(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run the live tracker (default: simulated cameras of the built-in scenario)");
  cmd->add_option("--udp", args->cli.udp,
                  "Send joint angles to HOST:PORT (default: the configuration's; built in: "
                  "127.0.0.1:7755)");
  cmd->add_option("--multicast-if", args->cli.multicast_if,
                  "With --udp to a multicast group: local interface address to send from");
  cmd->add_option("--multicast-ttl", args->cli.multicast_ttl,
                  "With --udp to a multicast group: hops (default 1: the local network)");
  cmd->add_option("--duration", args->duration_s,
                  "Stop after this many seconds (default: until Ctrl-C)");
  cmd->add_option("--stats", args->stats, "Write latency statistics to this JSON file at the end");
  cmd->add_option("--stats-interval", args->stats_interval_s,
                  "Print a progress line (fps, latency, drops) to stderr every S seconds "
                  "(default 5; 0: off)");
  add_rate_flag(*cmd, args->cli);
  add_loop_frames_flag(*cmd, args->cli);
  add_no_realtime_flag(*cmd, args->cli);
  cmd->add_flag("--no-iceoryx", args->cli.no_iceoryx, "Do not publish over iceoryx shared memory");
  cmd->add_flag(
      "--ros2", args->ros2,
      "Publish /joint_states, /tf, /mocap/<body>/pose and /mocap/unlabeled_markers over DDS "
      "as ROS 2 does (ROS_DOMAIN_ID; docs/ros2.md)");
  cmd->add_option("--foxglove", args->foxglove,
                  "Serve the Foxglove WebSocket live view on [ADDR:]PORT (default address "
                  "127.0.0.1)");
  cmd->add_option("--vrpn", args->vrpn,
                  "Serve VRPN trackers, one per body, on [ADDR:]PORT (default address 127.0.0.1, "
                  "VRPN's port 3883; docs/vrpn.md)");
  cmd->add_option("--config", args->config,
                  "Run the configuration FILE (cameras, rig, stages, outputs, thresholds; "
                  "docs/operations.md); flags given here override it");
  cmd->add_option("--check-config", args->check_config,
                  "Only validate the configuration FILE: exit 0, or 1 with a one-line error");
  cmd->callback([args, &exit_code] {
    if (!args->check_config.empty()) {
      exit_code = service::check_config_command(args->check_config);
      return;
    }
    exit_code = run_live(*args);
  });
}

const CommandRegistrar kRunRegistrar(60, register_run);

}  // namespace
}  // namespace mocap::app
