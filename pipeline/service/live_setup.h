// Design: from a validated RunConfig (src/config) to the objects `mocap run` starts:
// the cameras of the configured backend (opened and configured, wrapped for fault
// injection when asked), the tracker (FrameProcessor with the configured thresholds,
// rig, targets and model), the pipeline options (stage table overrides applied on top
// of pipeline::kDefaultStages) and the publishers' destinations. This is the one place
// that maps the configuration's plain data onto hal:: and pipeline:: types, because
// src/config is built before them. Setup code: allocates, returns one-line errors.
#pragma once

#include <array>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/run_config.h"
#include "config/tracking_assets.h"
#include "core/expected.h"
#include "formats/recording.h"
#include "hal/camera.h"
#include "hal/sim_camera.h"
#include "pipeline/pipeline.h"
#include "pipeline/publish/output_registry.h"
#include "track/frame_processor.h"

namespace mocap::node {
class NodeLink;
}

namespace mocap::service {

// Replay camera `position` of the configuration: the recording's camera named by
// `camera: NAME` (settings.recording_camera), else the same position; one-line error.
Expected<int> replay_camera_index(const Recording& recording, const config::CameraSettings& s,
                                  int position, const std::string& where);

// Command-line flags that override the configuration file (`mocap run`, `record`,
// `preview`: src/app/config_flags.h). Unset: the configuration's value. No default and no
// check of their own: resolve_run_config() checks them with the file's checks.
struct CliOverrides {
  std::optional<std::string> udp;  // --udp HOST:PORT replaces outputs.udp
  std::optional<double> rate_hz;   // --rate
  std::optional<int> loop_frames;  // --loop-frames (sim backend)
  bool no_realtime = false;        // --no-realtime
  bool no_iceoryx = false;         // --no-iceoryx
  // Registry outputs from flags (--ros2 -> {"ros2", "true"}, --foxglove P -> {"foxglove",
  // P}): replace or add to the configuration's outputs.NAME.
  std::vector<std::pair<std::string, std::string>> outputs;
  std::string multicast_if;          // --multicast-if (udp option; empty: unset)
  std::optional<int> multicast_ttl;  // --multicast-ttl (udp option, checked by the registry)
};

// The configuration file (or the built-in defaults when `path` is empty) with the
// command line's overrides applied and checked.
// targets_required = false: record/preview (config/tracking_assets.h).
Expected<config::RunConfig> resolve_run_config(const std::string& path, const CliOverrides& cli,
                                               bool targets_required = true);

// `mocap run --check-config FILE`: prints "FILE: OK (...)" on stdout and returns 0, or
// the one-line error on stderr and returns 1.
int check_config_command(const std::string& path);

// The output registry's requests (pipeline/publish/output_registry.h) of a resolved
// configuration: udp, iceoryx, then outputs.* in file order (flags last).
std::vector<publish::OutputRequest> output_requests(const config::RunConfig& cfg,
                                                    const CliOverrides& cli);

// pipeline::PipelineOptions from the configuration (stage table overrides included).
pipeline::PipelineOptions pipeline_options(const config::RunConfig& cfg);

class LiveSetup {
 public:
  // Renders the sim loop / opens the recording / opens the devices, configures the
  // cameras and builds the tracker. Progress lines go to `log` (may be null), prefixed
  // with `command` ("mocap run", "mocap record").
  // targets_required = false: without configured targets (replay, v4l2, libcamera) the
  // tracker gets none and reports 3D points only (record, preview).
  static Expected<std::unique_ptr<LiveSetup>> create(const config::RunConfig& cfg, std::FILE* log,
                                                     const char* command = "mocap run",
                                                     bool targets_required = true);

  // The rig's cameras (2..kMaxCameras) in rig order.
  std::vector<hal::Camera*> cameras() const {
    std::vector<hal::Camera*> v;
    for (const auto& c : cams_) v.push_back(c.get());
    return v;
  }
  // The tracker, to be moved into the pipeline (once).
  FrameProcessor take_processor() { return std::move(*processor_); }
  const pipeline::PipelineOptions& options() const noexcept { return options_; }
  // The rig, targets and joint model the tracker was built with (`mocap record` writes
  // them into its recording).
  const config::TrackingAssets& assets() const noexcept { return assets_; }
  // One line per camera fallback (hal::Camera::notice), empty entries left out.
  std::vector<std::string> notices() const;
  // Camera nodes (backend node): one line per node (messages, malformed, oversized,
  // clock offset) and per node camera (missing, late, duplicates, reconnects); empty
  // without node cameras. Report time.
  std::string node_report() const;
  // The same into the run's statistics (--stats): the round-trip legs as stages
  // (node_trigger_leg, node_work, node_transit), counters per node (node_<name>_messages,
  // _malformed, _oversized) and per node camera (node_missing_cam#, node_late_cam#,
  // node_duplicates_cam#, node_reconnects_cam#, node_inbox_full_cam#), gauges
  // node_<name>_clock_offset_us and node_<name>_round_trip_us. Nothing without nodes.
  void add_node_stats(pipeline::PipelineStats& st) const;

 private:
  LiveSetup() = default;
  std::shared_ptr<const hal::SimFrameLoop> loop_;
  std::shared_ptr<hal::SimTrigger> trigger_;
  std::shared_ptr<const Recording> recording_;
  std::shared_ptr<node::NodeLink> link_;  // backend node (pipeline/node/node_link.h)
  std::vector<std::unique_ptr<hal::Camera>> cams_;
  std::optional<FrameProcessor> processor_;
  config::TrackingAssets assets_;
  pipeline::PipelineOptions options_;
};

}  // namespace mocap::service
