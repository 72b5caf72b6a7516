// Design: the run configuration's keys of the camera nodes (issue 29; docs/operations.md,
// "Several PCs"), kept apart from the main reader (run_config.cpp):
//   cameras[i].trigger  free_run | external | software | central (central: a node's replay
//                       or software-triggered camera follows the central triggers)
//   cameras[i].camera   replay: the recording's camera NAME this camera plays
//   cameras[i].device   node backend: NODE/CAMERA
//   node:               {name, domain_id, timeout_ms, wait_s, detect_threads, trigger_lead_us}
//   pipeline.pair_by    sequence | timestamp, pipeline.pair_tolerance_us
// Each is checked here with the one-line "FILE: key: problem" error of the reader.
#include <string>
#include <vector>

#include "config/config_reader.h"
#include "config/run_config.h"
#include "core/camera_set.h"
#include "formats/yaml_read.h"

namespace mocap::config_detail {

using config::CameraBackend;

void read_node_camera_keys(const Section& s, config::CameraSettings& cam) {
  const std::optional<std::string> t = s.text("trigger");
  if (t && *t == "central") {
    if (cam.backend != CameraBackend::kReplay && cam.backend != CameraBackend::kV4l2 &&
        cam.backend != CameraBackend::kLibcamera)
      s.bad("trigger",
            std::string("'central' needs a replay or software-triggerable camera, not ") +
                config::to_string(cam.backend));
    cam.central_trigger = true;
    cam.trigger = TriggerMode::kSoftware;
  } else if (t) {
    cam.trigger = s.choice<TriggerMode>("trigger", {{"free_run", TriggerMode::kFreeRun},
                                                    {"external", TriggerMode::kExternal},
                                                    {"software", TriggerMode::kSoftware},
                                                    {"central", TriggerMode::kSoftware}});
  }
  if (const auto c = s.text("camera")) {
    if (cam.backend != CameraBackend::kReplay)
      s.bad("camera", "only replay cameras play a named camera of a recording");
    cam.recording_camera = *c;
  }
  if (cam.backend == CameraBackend::kNode) {
    const std::size_t slash = cam.device.find('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == cam.device.size() ||
        cam.device.find('/', slash + 1) != std::string::npos || cam.device.size() > 127)
      s.bad("device",
            "expected NODE/CAMERA (the node's name, its camera's name), got '" + cam.device + "'");
  }
}

void read_node_section(const YAML::Node& node, const std::vector<config::CameraSettings>& cameras,
                       config::NodeSettings& n) {
  const Section s(
      node, "node",
      {"name", "domain_id", "timeout_ms", "wait_s", "detect_threads", "trigger_lead_us"});
  if (const auto v = s.text("name")) {
    for (char ch : *v) {
      if (ch <= ' ' || ch > '~' || ch == '/')
        s.bad("name", "printable characters without spaces or '/', got '" + *v + "'");
    }
    if (v->size() > 63) s.bad("name", "at most 63 characters");
    n.name = *v;
  }
  if (const auto v = s.integer("domain_id", 0, 232)) n.domain_id = static_cast<std::uint32_t>(*v);
  if (const auto v = s.integer("timeout_ms", 1, 10'000)) n.timeout_ms = static_cast<int>(*v);
  if (const auto v = s.number("wait_s", 0.0, 3600.0)) n.wait_s = *v;
  if (const auto v = s.integer("trigger_lead_us", 0, kMaxTriggerLeadUs))
    n.trigger_lead_us = static_cast<int>(*v);
  if (const auto v = s.integer("detect_threads", 1, kMaxNodeCameras)) {
    std::int64_t central = 0;
    for (const config::CameraSettings& c : cameras) central += c.central_trigger ? 1 : 0;
    if (central == 0)
      s.bad("detect_threads", "no camera has trigger: central (the workers serve those cameras)");
    if (*v > central)
      s.bad("detect_threads", std::to_string(*v) + " workers for " + std::to_string(central) +
                                  " cameras with trigger: central (at most one per camera)");
    n.detect_threads = static_cast<int>(*v);
  }
}

void read_pair_keys(const Section& s, config::PipelineSettings& p) {
  if (const auto v = s.choice<config::PairBy>(
          "pair_by",
          {{"sequence", config::PairBy::kSequence}, {"timestamp", config::PairBy::kTimestamp}}))
    p.pair_by = *v;
  if (const auto v = s.integer("pair_tolerance_us", 1, 1'000'000))
    p.pair_tolerance_us = static_cast<int>(*v);
}

}  // namespace mocap::config_detail
