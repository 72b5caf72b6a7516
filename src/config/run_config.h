// Design: the configuration of `mocap run` (docs/operations.md, "Configuration file"),
// loaded from YAML and validated COMPLETELY at load time, so that `mocap run
// --check-config FILE` and the service's start fail with the spec's one-line error
// "FILE: key: problem" before any thread or camera is touched. Unknown keys are errors.
// Relative paths are resolved against the directory of the configuration file.
//
// This module is plain data: it is built before hal/ and pipeline/, so camera settings
// and the stage table are described here (the trigger mode and pacing enums are the
// shared ones of core/capture_modes.h), and the service
// layer (pipeline/service/live_setup.h) maps them onto hal::CameraConfig and
// pipeline::StageSpec. Settings left out of the file are std::nullopt / defaults and
// keep the backend's native value or the pipeline's default table.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera_set.h"
#include "core/capture_modes.h"
#include "core/expected.h"
#include "core/image.h"
#include "sim/scene_layouts.h"
#include "track/frame_processor.h"

namespace mocap::config {

enum class CameraBackend : std::uint8_t { kSim, kReplay, kV4l2, kLibcamera, kNode };

const char* to_string(CameraBackend b) noexcept;
const char* to_string(TriggerMode t) noexcept;

struct CameraSettings {
  CameraBackend backend = CameraBackend::kSim;
  // v4l2: the device node (/dev/video0); libcamera: a camera id or index ("0");
  // replay: the recording folder (absolute after loading); sim: empty; node: NODE/CAMERA
  // (a camera of a `mocap node`).
  std::string device;
  // replay: `camera: NAME`, the recording's camera this one plays (empty: the camera at
  // the same position).
  std::string recording_camera;
  // `trigger: central` (on a `mocap node` only): a replay or software-triggered camera
  // that follows the central tracker's triggers (trigger is then kSoftware).
  bool central_trigger = false;
  PixelFormat format = PixelFormat::kMono8;  // GREY | Y16
  int width = 0;                             // 0: the device's / recording's native size
  int height = 0;
  std::optional<int> exposure_us;
  std::optional<double> gain;
  std::optional<TriggerMode> trigger;
  std::optional<double> frame_rate_hz;  // free-run rate
  std::optional<int> buffers;           // driver buffers; default: ring depth + 3
};

// The pipeline's stage kinds, in the order of pipeline/stage_table.h (kDefaultStages):
// `pipeline.stages.<kind>`; `detect` is the rule of every camera's detect stage (its cpu
// is the first CPU of the rotation), `detect<k>` (k in 0..cameras-1) one camera's.
inline constexpr std::size_t kStageCount = 4;
inline constexpr std::array<const char*, kStageCount> kStageNames = {"capture", "detect",
                                                                     "identify", "publish"};

struct StageSettings {                      // unset: the default table's value
  std::optional<int> cpu;                   // -1: not pinned
  std::optional<int> priority;              // SCHED_FIFO 1..99; 0: default policy
  std::optional<std::uint32_t> ring_depth;  // input ring slots (capture: unused)
};

enum class PairBy : std::uint8_t { kSequence, kTimestamp };

struct PipelineSettings {
  double trigger_rate_hz = 100.0;
  PairBy pair_by = PairBy::kSequence;  // pipeline.pair_by
  int pair_tolerance_us = 1000;        // pipeline.pair_tolerance_us (pair_by: timestamp)
  TriggerPacing pacing = TriggerPacing::kPeriodic;
  bool realtime = true;      // CPU pinning + SCHED_FIFO (falls back when not permitted)
  bool every_frame = false;  // every stage works on every frame in order (not the newest)
  int catch_up_ms = 25;      // older frames a stage still takes in order; 0: the newest
  bool lock_memory = true;   // mlockall (falls back when not permitted)
  int cpu_latency_us = 0;    // PM QoS CPU latency while running; -1: none (rt/cpu_latency.h)
  int dequeue_timeout_ms = 20;
  std::array<StageSettings, kStageCount> stages{};
  std::array<StageSettings, kMaxCameras> detect_camera{};  // stages.detect<k>
};

// A further output of the `outputs:` map (ros2, foxglove, ... : any key other than udp
// and iceoryx), kept as text here and validated by the output registry
// (pipeline/publish/output_registry.h), which is built after this module.
struct OutputEntry {
  std::string name;                 // the key: the registry's output name
  std::vector<std::string> values;  // a scalar: one value; a list: one per item
  std::string where;                // "FILE: outputs.NAME (line N)" for error messages
  // The map form `NAME: {value: V, KEY: VALUE, ...}`: every key but `value`, in file
  // order (checked against the output's option keys by the registry).
  std::vector<std::pair<std::string, std::string>> options;
};

struct OutputSettings {
  std::vector<std::string> udp = {"127.0.0.1:7755"};  // "HOST:PORT" each, may be empty
  // The datagram version of each udp destination (1 or 2: the map form `{value: HOST:PORT,
  // version: 2}`); same length as udp.
  std::vector<std::uint16_t> udp_versions = {1};
  // The lead of each udp destination (ms; 0: the measured state; the map form's `lead_ms`:
  // the state predicted to publish + lead, pipeline/publish/lead.h); same length as udp.
  std::vector<double> udp_leads_ms = {0.0};
  bool iceoryx = true;
  double iceoryx_lead_ms = 0.0;   // `iceoryx: {value: true, lead_ms: L}`
  std::vector<OutputEntry> more;  // in file order
};

struct SimSettings {
  int loop_frames = 200;  // frames pre-rendered for the sim backend (humanoid: 100)
  // The key `sim.cameras` (2..8, the humanoid's ring 2..32; sim/scene_cameras.h: the
  // stereo pair, or 3..8 on an arc around the robot) sets RunConfig::cameras to that many
  // sim cameras: the count's one home is cameras.size().
  // The key `sim.rig`: render the simulated cameras through this rig.yaml (2..32 cameras,
  // any size, e.g. 4 x 1280x1024; its camera count is read at load time, the simulator
  // checks the rest) instead of the built-in ones; the tracker uses it too unless `rig:`
  // is given.
  std::string rig_path;                           // absolute; empty: the built-in cameras
  sim::SceneKind scene = sim::SceneKind::kLimbs;  // marker layout of the simulated robot
};

struct ServiceSettings {
  double status_interval_s = 1.0;  // how often STATUS= (and the journal line) is updated
  // The same line on stderr (the journal) every log_interval_s; 0: never (default: `mocap
  // run` already prints its progress line every --stats-interval).
  double log_interval_s = 0.0;
};

// Diagnostics and tests (docs/operations.md): make the live pipeline stall on purpose.
struct FaultSettings {
  std::uint64_t stall_after_frames = 0;  // camera 0 stops delivering after N frames; 0: off
};

// `node:` (docs/operations.md, "Several PCs"): on a `mocap node`, its name and DDS domain;
// on the central tracker (cameras of backend node), the domain and the fault timing.
struct NodeSettings {
  std::string name;  // empty: the host name (mocap node)
  std::uint32_t domain_id = 0;
  int timeout_ms = 100;  // central: a frame not arrived this long after its trigger is missing
  double wait_s = 10.0;  // central: how long start waits for every node to be discovered
  // node: the detection workers of its `trigger: central` cameras (1..their count); 0: the
  // default, min(those cameras, online CPUs)
  int detect_threads = 0;
  // central: how long before its instant a trigger is sent to the nodes (0..
  // kMaxTriggerLeadUs, at most half a trigger period is used); the nodes fire at the instant
  int trigger_lead_us = 1000;
};

// Which command reads the configuration: `mocap node` takes 1..8 cameras of its own PC
// and `trigger: central`, needs no targets; `mocap run` (central) takes 2..kMaxCameras.
enum class ConfigRole : std::uint8_t { kCentral, kNode };

struct RunConfig {
  std::string path;  // the file it was loaded from; empty for the built-in defaults
  // The rig's cameras in rig order, kMinCameras..kMaxCameras, all of one backend. Without
  // a `cameras:` list: sim.cameras simulated cameras.
  std::vector<CameraSettings> cameras = std::vector<CameraSettings>(2);
  std::string rig_path;      // absolute; empty: the backend's (sim scene / recording)
  std::string targets_path;  // absolute; empty: the sim scene's (sim only)
  std::string model_path;    // absolute; empty: sim: the scene's true model; else none
  PipelineSettings pipeline;
  OutputSettings outputs;
  TrackerConfig tracker;  // detection, stereo and identification thresholds
  SimSettings sim;
  ServiceSettings service;
  FaultSettings faults;
  NodeSettings node;
};

// The ranges of the settings a command-line flag may also set, and their one check:
// the file's keys (pipeline.trigger_rate_hz, sim.loop_frames) and the flags (--rate,
// --loop-frames) are validated by these, so both accept exactly the same values.
inline constexpr int kMaxCatchUpMs = 10'000;  // pipeline.catch_up_ms
inline constexpr int kMinLoopFrames = 2;
inline constexpr int kMaxLoopFrames = 2000;
inline constexpr int kHumanoidLoopFrames = 100;  // sim.loop_frames' default for the humanoid
// `where` names the key or flag in the error ("--rate: must be in [0.01, 10000] Hz, got 0").
Expected<void> check_trigger_rate_hz(const std::string& where, double hz);
Expected<void> check_loop_frames(const std::string& where, long long frames);

// The configuration `mocap run` uses without a file: the simulated stereo pair of the
// built-in scenario, UDP to 127.0.0.1:7755 and iceoryx.
// (`sim: {cameras: N}` in a file gives N simulated cameras.)
RunConfig default_run_config();

// Parses, validates every key, resolves paths and loads the referenced rig, targets and
// model files (and the recording of the replay backend) to check that they fit together
// with the thresholds (FrameProcessor::create). Cameras are NOT opened.
// targets_required = false: record/preview (tracking_assets.h).
Expected<RunConfig> load_run_config(const std::string& path, bool targets_required = true,
                                    ConfigRole role = ConfigRole::kCentral);

// "HOST:PORT" with a non-empty host and a port in 1..65535 (the publisher resolves the
// host). Error names `where`.
Expected<void> check_host_port(const std::string& file, const std::string& where,
                               const std::string& value);

}  // namespace mocap::config
