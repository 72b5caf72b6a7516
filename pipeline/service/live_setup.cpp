// Design: see live_setup.h.
#include "pipeline/service/live_setup.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "config/tracking_assets.h"
#include "hal/fault_camera.h"
#include "hal/replay_camera.h"
#include "hal/v4l2_camera.h"
#ifdef MOCAP_HAVE_LIBCAMERA
#include "hal/libcamera_camera.h"
#endif
#ifdef MOCAP_HAVE_NODES
#include "pipeline/node/node_camera.h"
#endif

namespace mocap::service {

using config::CameraBackend;

static_assert(config::kStageCount == pipeline::kStageKinds,
              "config::kStageNames lists the stage kinds of pipeline/stage_table.h");

namespace {

// A lead as an option value: microsecond resolution, as the messages carry it.
std::string format_lead_ms(double lead_ms) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", lead_ms);
  return buf;
}

}  // namespace

Expected<config::RunConfig> resolve_run_config(const std::string& path, const CliOverrides& cli,
                                               bool targets_required) {
  config::RunConfig cfg = config::default_run_config();
  if (!path.empty()) {
    auto loaded = config::load_run_config(path, targets_required);
    if (!loaded) return loaded.error();
    cfg = std::move(loaded).value();
  }
  if (cli.udp) {
    if (auto r = config::check_host_port("--udp", "", *cli.udp); !r) return r.error();
    cfg.outputs.udp = {*cli.udp};
    cfg.outputs.udp_versions = {1};
    cfg.outputs.udp_leads_ms = {0.0};
  }
  if (cli.rate_hz) {
    if (auto r = config::check_trigger_rate_hz("--rate", *cli.rate_hz); !r) return r.error();
    cfg.pipeline.trigger_rate_hz = *cli.rate_hz;
  }
  if (cli.loop_frames) {
    if (auto r = config::check_loop_frames("--loop-frames", *cli.loop_frames); !r) return r.error();
    cfg.sim.loop_frames = *cli.loop_frames;
  }
  if (cli.no_realtime) cfg.pipeline.realtime = false;
  if (cli.no_iceoryx) cfg.outputs.iceoryx = false;
  for (const auto& flag : cli.outputs) {  // a flag sets the value, keeps the options
    const std::string& name = flag.first;
    auto& more = cfg.outputs.more;
    auto it = std::find_if(more.begin(), more.end(),
                           [&](const config::OutputEntry& e) { return e.name == name; });
    if (it == more.end()) it = more.insert(more.end(), config::OutputEntry{name, {}, "", {}});
    it->values = {flag.second};
    it->where = "--" + name;
  }
  if (auto r = publish::check_outputs(output_requests(cfg, cli)); !r) return r.error();
  return cfg;
}

std::vector<publish::OutputRequest> output_requests(const config::RunConfig& cfg,
                                                    const CliOverrides& cli) {
  const std::string file = cfg.path.empty() ? std::string("outputs") : cfg.path + ": outputs";
  std::vector<publish::OutputRequest> v;
  publish::OutputRequest udp{"udp", cfg.outputs.udp, file + ".udp", {}};
  std::string versions;  // "1,2,...": one per destination
  for (std::size_t i = 0; i < cfg.outputs.udp.size(); ++i)
    versions +=
        (i ? "," : "") +
        std::to_string(i < cfg.outputs.udp_versions.size() ? cfg.outputs.udp_versions[i] : 1);
  if (!versions.empty()) udp.options.emplace_back("versions", versions);
  // "0,5,..." (ms): one lead per destination, given only when one is set.
  const auto& leads = cfg.outputs.udp_leads_ms;
  if (std::any_of(leads.begin(), leads.end(), [](double l) { return l > 0.0; })) {
    std::string text;
    for (std::size_t i = 0; i < cfg.outputs.udp.size(); ++i)
      text += (i ? "," : "") + format_lead_ms(i < leads.size() ? leads[i] : 0.0);
    udp.options.emplace_back("leads_ms", text);
  }
  if (!cli.multicast_if.empty()) udp.options.emplace_back("multicast_if", cli.multicast_if);
  if (cli.multicast_ttl)
    udp.options.emplace_back("multicast_ttl", std::to_string(*cli.multicast_ttl));
  v.push_back(std::move(udp));
  v.push_back({"iceoryx", {cfg.outputs.iceoryx ? "true" : "false"}, file + ".iceoryx", {}});
  if (cfg.outputs.iceoryx_lead_ms > 0.0)
    v.back().options.emplace_back("lead_ms", format_lead_ms(cfg.outputs.iceoryx_lead_ms));
  for (const config::OutputEntry& e : cfg.outputs.more)
    v.push_back({e.name, e.values, e.where, e.options});
  return v;
}

int check_config_command(const std::string& path) {
  auto cfg = config::load_run_config(path);
  if (!cfg) {
    std::fprintf(stderr, "mocap: %s\n", cfg.error().message.c_str());
    return 1;
  }
  if (auto r = publish::check_outputs(output_requests(*cfg, CliOverrides{})); !r) {
    std::fprintf(stderr, "mocap: %s\n", r.error().message.c_str());
    return 1;
  }
  std::string more;
  for (const config::OutputEntry& e : cfg->outputs.more) more += ", " + e.name;
  std::printf("%s: OK (%s cameras, %.0f Hz, %zu UDP destination(s), iceoryx %s%s)\n", path.c_str(),
              config::to_string(cfg->cameras[0].backend), cfg->pipeline.trigger_rate_hz,
              cfg->outputs.udp.size(), cfg->outputs.iceoryx ? "on" : "off", more.c_str());
  return 0;
}

namespace {

// The configured settings on top of `base` (the backend's native configuration).
hal::CameraConfig camera_config(const config::CameraSettings& s, hal::CameraConfig base,
                                const CameraModel& rig_camera, std::uint32_t detect_ring_depth) {
  if (s.backend == CameraBackend::kV4l2 || s.backend == CameraBackend::kLibcamera) {
    base.format = s.format;
    base.width = s.width != 0 ? s.width : rig_camera.width;
    base.height = s.height != 0 ? s.height : rig_camera.height;
    if (s.exposure_us) base.exposure_us = *s.exposure_us;
    if (s.gain) base.gain = *s.gain;
  }
  if (s.trigger) base.trigger = *s.trigger;
  if (s.frame_rate_hz) base.frame_rate_hz = *s.frame_rate_hz;
  base.buffer_count = s.buffers ? *s.buffers : static_cast<int>(detect_ring_depth + 3);
  return base;
}

// A replay rig with a software-triggered camera: its external-triggered replay cameras
// follow that master's triggers (a rig of external cameras only free-runs, as before).
bool replay_has_master(const config::RunConfig& cfg) {
  for (const config::CameraSettings& c : cfg.cameras)
    if (c.trigger && *c.trigger == hal::TriggerMode::kSoftware) return true;
  return false;
}

std::string index_name(std::size_t c) { return "cameras[" + std::to_string(c) + "]"; }

void say(std::FILE* log, const std::string& line, const char* command = "mocap run") {
  if (log != nullptr) std::fprintf(log, "%s: %s\n", command, line.c_str());
}

}  // namespace

Expected<std::unique_ptr<LiveSetup>> LiveSetup::create(const config::RunConfig& cfg, std::FILE* log,
                                                       const char* command, bool targets_required) {
  std::unique_ptr<LiveSetup> s(new LiveSetup());
  s->options_ = pipeline_options(cfg);
  const CameraBackend backend = cfg.cameras[0].backend;
  Expected<config::TrackingAssets> assets = Error{};
  std::shared_ptr<hal::LibcameraSession> session;
  const std::size_t n = cfg.cameras.size();
  std::vector<std::unique_ptr<hal::Camera>> cams(n);
  std::vector<hal::CameraConfig> native(n);
  if (backend == CameraBackend::kSim) {
    say(log,
        "rendering the simulated camera loop (" + std::to_string(cfg.sim.loop_frames) +
            " frames x " + std::to_string(n) + " cameras)...",
        command);
    auto loop = hal::SimFrameLoop::render(config::sim_options(cfg));
    if (!loop) return loop.error();
    s->loop_ = std::move(loop).value();
    say(log,
        "simulated loop ready (" + std::to_string(s->loop_->memory_bytes() / 1'000'000) + " MB)",
        command);
    s->trigger_ = std::make_shared<hal::SimTrigger>(s->loop_);
    const sim::SimScene& scene = s->loop_->scene();
    assets = config::load_tracking_assets(cfg, &scene.rig, &scene.targets, &scene.joints_true);
    for (int c = 0; c < static_cast<int>(n); ++c) {
      auto cam = hal::SimCamera::open(s->trigger_, c);
      if (!cam) return cam.error();
      native[static_cast<std::size_t>(c)] = (*cam)->native_config();
      cams[static_cast<std::size_t>(c)] = std::move(cam).value();
    }
  } else if (backend == CameraBackend::kReplay) {
    auto rec = Recording::open(cfg.cameras[0].device);
    if (!rec) return rec.error();
    s->recording_ = std::make_shared<const Recording>(std::move(rec).value());
    assets = config::load_tracking_assets(cfg, &s->recording_->rig(), nullptr, nullptr,
                                          targets_required);
    if (assets && s->recording_->rig().cameras.size() != n) {
      return make_error(cfg.path.empty() ? std::string(command) : cfg.path, "cameras",
                        std::to_string(n) + " cameras, the recording has " +
                            std::to_string(s->recording_->rig().cameras.size()));
    }
    for (int c = 0; c < static_cast<int>(n); ++c) {
      auto index = replay_camera_index(*s->recording_, cfg.cameras[static_cast<std::size_t>(c)], c,
                                       cfg.path.empty() ? std::string(command) : cfg.path);
      if (!index) return index.error();
      auto cam = hal::ReplayCamera::open(s->recording_, *index, hal::ReplayPacing::kRecordedTiming);
      if (!cam) return cam.error();
      native[static_cast<std::size_t>(c)] = (*cam)->native_config();
      cams[static_cast<std::size_t>(c)] = std::move(cam).value();
    }
  } else if (backend == CameraBackend::kNode) {
    assets = config::load_tracking_assets(cfg, nullptr, nullptr, nullptr, targets_required);
    if (!assets) return assets.error();
#ifdef MOCAP_HAVE_NODES
    auto link = node::NodeLink::create(cfg.node.domain_id, cfg.node.wait_s, cfg.pipeline.realtime,
                                       std::int64_t{cfg.node.trigger_lead_us} * 1000);
    if (!link) return link.error();
    s->link_ = std::move(link).value();
    for (std::size_t c = 0; c < n; ++c) {
      auto cam = node::NodeCamera::open(s->link_, cfg.cameras[c].device,
                                        cfg.tracker.detect.max_blobs, cfg.node.timeout_ms);
      if (!cam) return make_error(cfg.path, index_name(c), cam.error().message);
      native[c] = (*cam)->native_config();
      cams[c] = std::move(cam).value();
    }
    say(log,
        "camera nodes: DDS domain " + std::to_string(cfg.node.domain_id) + ", " +
            std::to_string(n) + " cameras",
        command);
#else
    return make_error(cfg.path, "cameras[0].backend",
                      "camera nodes are not built in (Cyclone DDS missing at build time)");
#endif
  } else {
    assets = config::load_tracking_assets(cfg, nullptr, nullptr, nullptr, targets_required);
    if (!assets) return assets.error();
    for (std::size_t c = 0; c < n; ++c) {
      const std::string& device = cfg.cameras[c].device;
      if (backend == CameraBackend::kV4l2) {
        auto cam = hal::V4l2Camera::open(device);
        if (!cam) return cam.error();
        cams[c] = std::move(cam).value();
      } else {
#ifdef MOCAP_HAVE_LIBCAMERA
        if (!session) {
          auto got = hal::LibcameraSession::get();
          if (!got) return got.error();
          session = std::move(got).value();
        }
        auto cam = hal::LibcameraCamera::open(session, device);
        if (!cam) return cam.error();
        cams[c] = std::move(cam).value();
#else
        return make_error(
            cfg.path, "cameras[0].backend",
            "libcamera support is not built in (libcamera-dev missing at build time)");
#endif
      }
    }
  }
  if (!assets) return assets.error();

  if (assets->rig.cameras.size() != n) {
    return make_error(
        cfg.path.empty() ? std::string(command) : cfg.path, "cameras",
        std::to_string(n) + " cameras, the rig has " + std::to_string(assets->rig.cameras.size()));
  }
  for (std::size_t c = 0; c < n; ++c) {
    const std::uint32_t depth =  // the stage table's detect rule (CPU count irrelevant here)
        pipeline::resolve_stage(s->options_.stages, pipeline::StageId::detect(static_cast<int>(c)),
                                1)
            .ring_depth;
    hal::CameraConfig want =
        camera_config(cfg.cameras[c], native[c], assets->rig.cameras[c], depth);
    if (backend == CameraBackend::kReplay && want.trigger == hal::TriggerMode::kExternal &&
        replay_has_master(cfg)) {
      // A lab wires the slave's trigger input to the master's strobe: each master trigger
      // exposes the slave too. In a replay that wire is the tracker's own trigger.
      want.trigger = hal::TriggerMode::kSoftware;
      say(log,
          cams[c]->name() +
              ": trigger: external in a replay follows the software-triggered cameras' "
              "triggers (the master's pulse), frame for frame",
          command);
    }
    if (auto r = cams[c]->configure(want); !r) return r.error();
    if (c == 0 && cfg.faults.stall_after_frames > 0) {
      say(log,
          "fault injection: camera 0 stalls after " +
              std::to_string(cfg.faults.stall_after_frames) + " frames",
          command);
      const hal::FaultRule stall{hal::Fault::kStall, cfg.faults.stall_after_frames,
                                 hal::FaultRule::kForever, 0};
      auto faulty = hal::FaultCamera::wrap(std::move(cams[c]), {stall});
      if (!faulty) return faulty.error();
      cams[c] = std::move(faulty).value();
    }
  }
  s->cams_ = std::move(cams);

  const JointModel* model = assets->model ? &*assets->model : nullptr;
  if (model == nullptr)
    say(log, "note: no joint model: poses are tracked, no joint angles are sent", command);
  auto proc = FrameProcessor::create(assets->rig, assets->targets, model, cfg.tracker);
  if (!proc) return proc.error();
  for (const std::string& w : proc->warnings()) say(log, "warning: " + w, command);
  s->processor_.emplace(std::move(proc).value());
  s->assets_ = std::move(assets).value();
  return s;
}

Expected<int> replay_camera_index(const Recording& recording, const config::CameraSettings& s,
                                  int position, const std::string& where) {
  const auto& cams = recording.rig().cameras;
  if (s.recording_camera.empty()) return position;
  std::string names;
  for (std::size_t i = 0; i < cams.size(); ++i) {
    if (cams[i].name == s.recording_camera) return static_cast<int>(i);
    names += (i ? ", " : "") + cams[i].name;
  }
  return make_error(
      where, "cameras[" + std::to_string(position) + "].camera",
      "the recording has no camera '" + s.recording_camera + "' (it has " + names + ")");
}

std::string LiveSetup::node_report() const {
  std::string out;
#ifdef MOCAP_HAVE_NODES
  if (!link_) return out;
  out += link_->report();
  for (const auto& c : cams_) {
    const auto* nc = dynamic_cast<const node::NodeCamera*>(c.get());
    if (nc == nullptr) continue;
    out += nc->name() + ": frames " + std::to_string(nc->counters().frames.get()) + ", missing " +
           std::to_string(nc->counters().missing.get()) + ", late " + std::to_string(nc->late()) +
           ", duplicates " + std::to_string(nc->duplicates()) + ", reconnects " +
           std::to_string(nc->reconnects()) + ", inbox_full " + std::to_string(nc->inbox_full()) +
           "\n";
  }
#endif
  return out;
}

void LiveSetup::add_node_stats(pipeline::PipelineStats& st) const {
#ifdef MOCAP_HAVE_NODES
  if (!link_) return;
  st.latency.emplace_back("node_trigger_leg", link_->trigger_leg().stats());
  st.latency.emplace_back("node_work", link_->node_work().stats());
  st.latency.emplace_back("node_transit", link_->transit().stats());
  for (const auto& n : link_->nodes()) {
    const std::string p = "node_" + n->name + "_";
    st.counters.emplace_back(p + "messages", n->messages.get());
    st.counters.emplace_back(p + "malformed", n->malformed.get());
    st.counters.emplace_back(p + "oversized", n->oversized.get());
    st.gauges.emplace_back(p + "clock_offset_us",
                           static_cast<double>(n->offset_ns.load(std::memory_order_relaxed)) / 1e3);
    st.gauges.emplace_back(
        p + "round_trip_us",
        static_cast<double>(n->round_trip_ns.load(std::memory_order_relaxed)) / 1e3);
  }
  st.counters.emplace_back("nodes_unknown_messages", link_->unknown());
  for (std::size_t c = 0; c < cams_.size(); ++c) {
    const auto* nc = dynamic_cast<const node::NodeCamera*>(cams_[c].get());
    if (nc == nullptr) continue;
    const std::string k = std::to_string(c);
    st.counters.emplace_back("node_missing_cam" + k, nc->counters().missing.get());
    st.counters.emplace_back("node_late_cam" + k, nc->late());
    st.counters.emplace_back("node_duplicates_cam" + k, nc->duplicates());
    st.counters.emplace_back("node_reconnects_cam" + k, nc->reconnects());
    st.counters.emplace_back("node_inbox_full_cam" + k, nc->inbox_full());
  }
#else
  (void)st;
#endif
}

std::vector<std::string> LiveSetup::notices() const {
  std::vector<std::string> out;
  for (const auto& c : cams_) {
    if (c && !c->notice().empty()) out.push_back(c->name() + ": " + c->notice());
  }
  return out;
}

}  // namespace mocap::service
