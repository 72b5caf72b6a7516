// Design: `mocap node [--config FILE] [--duration SECONDS]` and `mocap node --check-config
// FILE` (issue 29; spec extension "Blob recordings and camera nodes"): the capture and detection of
// the configuration's cameras (1..8, this PC's) and every camera frame's blob list published over
// DDS (docs/formats.md, "Camera nodes"). Structure: load the configuration (ConfigRole::kNode: no
// tracker) -> open and configure the cameras (replay with `camera: NAME`, v4l2, libcamera;
// `trigger: central` follows the central tracker) -> NodeSender (DDS threads)
// + NodeRunner (real-time detection workers, node.detect_threads) -> run until --duration,
// SIGINT/SIGTERM or the end of every replay -> flush (the end-of-stream messages reach the central)
// -> one report line per camera on stdout. --check-config stops after the checks (plan_node: the
// configuration, the backend, the replay recording and its cameras) and prints a summary, as `mocap
// run --check-config` does; it needs neither cameras nor DDS.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/command_registry.h"
#include "config/run_config.h"
#include "formats/recording.h"
#include "hal/replay_camera.h"
#include "hal/v4l2_camera.h"
#include "pipeline/service/live_setup.h"
#ifdef MOCAP_HAVE_NODES
#include "pipeline/node/node_runner.h"
#endif

namespace mocap::app {
namespace {

std::atomic<bool> g_node_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "used from a signal handler");

extern "C" void on_node_signal(int) {
  g_node_stop.store(true, std::memory_order_relaxed);  // lock-free: async-signal-safe
}

struct NodeArgs {
  std::string config;
  std::string check_config;  // --check-config FILE
  double duration_s = 0.0;   // 0: until SIGINT/SIGTERM or the replays' end
};

std::string host_name() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0 || buf[0] == '\0') return "node";
  std::string s(buf);
  return s.substr(0, 63);
}

// One camera of the node's configuration, checked without opening it.
struct NodeCameraPlan {
  std::string name;          // the published camera name (the central's NODE/CAMERA)
  int recording_index = -1;  // replay: the recording's camera it plays
};

// What `mocap node` runs, from a loaded configuration: the checks that need more than
// the configuration's own keys (the backend, v4l2 sizes, the replay recording and its
// cameras, unique published names), shared by --check-config and the run. Opens the
// replay recording (its rig and frames.csv), never a camera or DDS.
struct NodePlan {
  std::string name;
  std::shared_ptr<const Recording> recording;  // replay cameras
  std::vector<NodeCameraPlan> cameras;
};

Expected<NodePlan> plan_node(const config::RunConfig& cfg) {
  NodePlan plan;
  plan.name = cfg.node.name.empty() ? host_name() : cfg.node.name;
  for (std::size_t c = 0; c < cfg.cameras.size(); ++c) {
    const config::CameraSettings& s = cfg.cameras[c];
    const std::string key = "cameras[" + std::to_string(c) + "]";
    NodeCameraPlan cam;
    if (s.backend == config::CameraBackend::kReplay) {
      if (!plan.recording) {
        auto rec = Recording::open(s.device);
        if (!rec) return make_error(cfg.path, key + ".device", rec.error().message);
        plan.recording = std::make_shared<const Recording>(std::move(rec).value());
      }
      auto index = service::replay_camera_index(*plan.recording, s, static_cast<int>(c), cfg.path);
      if (!index) return index.error();
      const auto& rig = plan.recording->rig().cameras;
      if (*index >= static_cast<int>(rig.size()))
        return make_error(cfg.path, key,
                          "the recording has only " + std::to_string(rig.size()) + " cameras");
      cam.recording_index = *index;
      cam.name = rig[static_cast<std::size_t>(*index)].name;
    } else if (s.backend == config::CameraBackend::kV4l2) {
      if (s.width == 0)
        return make_error(cfg.path, key + ".width", "a node's v4l2 camera needs width and height");
      cam.name = "cam" + std::to_string(c);
    } else {
      return make_error(cfg.path, key + ".backend",
                        std::string(config::to_string(s.backend)) +
                            " cameras are not supported on a node (replay or v4l2)");
    }
    for (std::size_t o = 0; o < plan.cameras.size(); ++o) {
      if (plan.cameras[o].name == cam.name)
        return make_error(cfg.path, key,
                          "publishes camera '" + cam.name + "' as cameras[" + std::to_string(o) +
                              "] does (the central could not tell them apart)");
    }
    plan.cameras.push_back(cam);
  }
  return plan;
}

// `mocap node --check-config FILE`: as `mocap run --check-config` (exit 0 and "FILE: OK
// (...)" on stdout, or exit 1 and the one-line error on stderr); no camera, no DDS.
int check_node_config(const std::string& path) {
  auto cfg = config::load_run_config(path, false, config::ConfigRole::kNode);
  Expected<NodePlan> plan = cfg ? plan_node(*cfg) : Expected<NodePlan>(cfg.error());
  if (!plan) {
    std::fprintf(stderr, "mocap: %s\n", plan.error().message.c_str());
    return 1;
  }
  std::string names;
  int central = 0;
  for (std::size_t c = 0; c < plan->cameras.size(); ++c) {
    names += (c ? " " : "") + plan->cameras[c].name;
    central += cfg->cameras[c].central_trigger ? 1 : 0;
  }
  std::printf("%s: OK (node %s, %zu %s cameras: %s; %d with trigger central; DDS domain %u)\n",
              path.c_str(), plan->name.c_str(), plan->cameras.size(),
              config::to_string(cfg->cameras[0].backend), names.c_str(), central,
              cfg->node.domain_id);
  return 0;
}

#ifdef MOCAP_HAVE_NODES
int run_node(const NodeArgs& a) {
  if (a.config.empty()) return fail("--config: required (the node's configuration FILE)");
  if (a.duration_s < 0.0) return fail("--duration: must be >= 0");
  auto cfg = config::load_run_config(a.config, false, config::ConfigRole::kNode);
  if (!cfg) return fail(cfg.error().message);
  auto plan = plan_node(*cfg);
  if (!plan) return fail(plan.error().message);
  const std::string& name = plan->name;
  std::vector<std::unique_ptr<hal::Camera>> cams;
  std::vector<node::NodeCameraSpec> specs;
  std::vector<bool> central;
  for (std::size_t c = 0; c < cfg->cameras.size(); ++c) {
    const config::CameraSettings& s = cfg->cameras[c];
    const NodeCameraPlan& p = plan->cameras[c];
    node::NodeCameraSpec spec;
    spec.name = p.name;
    hal::CameraConfig want;
    if (s.backend == config::CameraBackend::kReplay) {
      auto cam = hal::ReplayCamera::open(plan->recording, p.recording_index,
                                         hal::ReplayPacing::kRecordedTiming);
      if (!cam) return fail(cam.error().message);
      want = (*cam)->native_config();
      spec.replay = true;
      if (s.central_trigger) spec.seekable = cam->get();  // plays the frame a trigger names
      cams.push_back(std::move(cam).value());
    } else {  // v4l2 (plan_node)
      auto cam = hal::V4l2Camera::open(s.device);
      if (!cam) return fail(cam.error().message);
      want.format = s.format;
      want.width = s.width;
      want.height = s.height;
      if (s.exposure_us) want.exposure_us = *s.exposure_us;
      if (s.gain) want.gain = *s.gain;
      cams.push_back(std::move(cam).value());
    }
    if (s.trigger) want.trigger = *s.trigger;
    if (s.frame_rate_hz) want.frame_rate_hz = *s.frame_rate_hz;
    want.buffer_count = s.buffers ? *s.buffers : 4;
    if (auto r = cams.back()->configure(want); !r) return fail(r.error().message);
    spec.camera = cams.back().get();
    spec.central = s.central_trigger;
    central.push_back(s.central_trigger);
    specs.push_back(spec);
  }
  auto sender = node::NodeSender::create(cfg->node.domain_id, central, 8, cfg->pipeline.realtime);
  if (!sender) return fail(sender.error().message);
  node::NodeOptions opt;
  opt.node_name = name;
  opt.trigger_rate_hz = cfg->pipeline.trigger_rate_hz;
  opt.realtime = cfg->pipeline.realtime;
  opt.detect_threads = cfg->node.detect_threads;
  auto runner = node::NodeRunner::create(specs, cfg->tracker.detect, opt, **sender);
  if (!runner) return fail(runner.error().message);

  struct sigaction sa {};
  sa.sa_handler = on_node_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  if (auto r = (*sender)->start(); !r) return fail(r.error().message);
  if (auto r = (*runner)->start(); !r) return fail(r.error().message);
  for (const std::string& n : (*runner)->notes())
    std::fprintf(stderr, "mocap node: note: %s\n", n.c_str());
  for (const std::string& n : (*sender)->notes())
    std::fprintf(stderr, "mocap node: note: %s\n", n.c_str());
  std::fprintf(stderr,
               "mocap node: %s publishing %zu cameras on DDS domain %u (%d detection workers)\n",
               name.c_str(), specs.size(), cfg->node.domain_id, (*runner)->workers());
  const auto t0 = std::chrono::steady_clock::now();
  bool ended = false;
  while (!g_node_stop.load(std::memory_order_relaxed)) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (a.duration_s > 0.0 && t >= a.duration_s) break;
    if ((*runner)->finished()) {
      ended = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  (*runner)->stop();
  (*sender)->stop(true);  // the queued messages (the end of stream) reach the central
  if (ended) std::fprintf(stderr, "mocap node: the recording ended\n");
  std::fputs((*runner)->report().c_str(), stdout);
  std::printf(
      "sent %llu messages, %llu write errors, %llu central triggers received, %llu dropped, "
      "%llu after their instant, %llu with an instant too far ahead (clocks apart)\n",
      static_cast<unsigned long long>((*sender)->sent()),
      static_cast<unsigned long long>((*sender)->write_errors()),
      static_cast<unsigned long long>((*sender)->triggers_received()),
      static_cast<unsigned long long>((*sender)->triggers_dropped()),
      static_cast<unsigned long long>((*sender)->triggers_late()),
      static_cast<unsigned long long>((*sender)->triggers_unsynced()));
  return 0;
}
#else
int run_node(const NodeArgs&) {
  return fail("mocap node: not built in (Cyclone DDS was missing at build time)");
}
#endif

void register_node(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<NodeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "node", "Camera node: capture and detect this PC's cameras, publish their blobs over DDS");
  cmd->add_option("--config", args->config,
                  "The node's configuration FILE (cameras 1..8, node: {name, domain_id})");
  cmd->add_option("--duration", args->duration_s,
                  "Stop after this many seconds (default: until Ctrl-C or the replays end)");
  cmd->add_option("--check-config", args->check_config,
                  "Only validate the node configuration FILE (no camera, no DDS): exit 0, or 1 "
                  "with a one-line error");
  cmd->callback([args, &exit_code] {
    exit_code =
        args->check_config.empty() ? run_node(*args) : check_node_config(args->check_config);
  });
}

const CommandRegistrar kNodeRegistrar(61, register_node);

}  // namespace
}  // namespace mocap::app
