// Design: a tiny but valid recording for the service tests (no rendering, so the tests
// stay fast under the sanitizers): a two-camera 64x48 rig, one rigid target, and
// `frames` dark binary PGM images per camera. Frames flow through the whole live
// pipeline (nothing is detected, every frame is still published).
#pragma once

#include <string>

#include "tests/support/test_support.h"

namespace mocap::test {

inline void write_tiny_recording(const std::string& dir, int frames) {
  const char* cam = R"(    width: 64
    height: 48
    fx: 80.0
    fy: 80.0
    cx: 31.5
    cy: 23.5
    distortion: [0, 0, 0, 0, 0]
    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]
)";
  write_file(dir + "/rig.yaml", std::string("cameras:\n  - name: cam0\n") + cam +
                                    "    t: [0, 0, 0]\n  - name: cam1\n" + cam +
                                    "    t: [-200, 0, 0]\n");
  write_file(dir + "/targets.yaml",
             "bodies:\n  - name: box\n    markers:\n      - [0, 0, 0]\n      - [60, 0, 0]\n"
             "      - [0, 45, 0]\n      - [10, 20, 35]\n");
  std::string csv = "frame,timestamp_ns\n";
  std::string pgm = "P5\n64 48\n255\n" + std::string(64 * 48, '\x0a');
  for (int f = 0; f < frames; ++f) {
    csv += std::to_string(f) + "," + std::to_string(std::int64_t{f} * 10'000'000) + "\n";
    char name[16];
    std::snprintf(name, sizeof name, "%06d.pgm", f);
    write_file(dir + "/cam0/" + name, pgm);
    write_file(dir + "/cam1/" + name, pgm);
  }
  write_file(dir + "/frames.csv", csv);
}

// A run configuration replaying that recording at 100 Hz (software trigger), without
// real-time scheduling, outputs or periodic log lines.
inline std::string tiny_replay_config(const std::string& rec_dir, const std::string& extra) {
  return "cameras:\n"
         "  - {backend: replay, device: " +
         rec_dir +
         ", trigger: software}\n"
         "  - {backend: replay, device: " +
         rec_dir +
         ", trigger: software}\n"
         "targets: " +
         rec_dir +
         "/targets.yaml\n"
         "pipeline: {trigger_rate_hz: 100, realtime: false, lock_memory: false}\n"
         "outputs: {udp: [], iceoryx: false}\n"
         "service: {status_interval_s: 0.1}\n" +
         extra;
}

}  // namespace mocap::test
