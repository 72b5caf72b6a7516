// `mocap node --check-config FILE` (issue 29), as a user runs it: exit 0 and one
// "FILE: OK (...)" summary line for a good node configuration (the shipped example, whose
// /dev/video0 is never opened, and replay cameras of the node_recording fixture); exit 1
// and exactly one line naming the file and the key for each kind of bad input (an unknown
// key, a backend a node cannot run, a recording camera that does not exist, two cameras
// publishing the same name, 9 cameras: a node publishes at most 8; more detection workers
// than central-triggered cameras, or none to serve; a trigger lead beyond 0.1 s). No DDS
// and no camera is touched.
#include <gtest/gtest.h>

#include <string>

#include "tests/support/test_support.h"

namespace mocap::test {
namespace {

#ifndef MOCAP_TEST_NODE_RECORDING
#define MOCAP_TEST_NODE_RECORDING "node_recording"
#endif

std::string check(const std::string& file, int& exit_code) {
  const RunResult r = run_mocap("node --check-config '" + file + "'", 60);
  exit_code = r.exit_code;
  return r.output;
}

TEST(NodeCheckConfig, AcceptsTheShippedExampleWithoutOpeningItsCamera) {
  int rc = -1;
  const std::string out = check(source_dir() + "/deploy/mocap-node.yaml", rc);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("mocap-node.yaml: OK (node node-a, 1 v4l2 cameras: cam0; 0 with trigger "
                     "central; DDS domain 0)\n"),
            std::string::npos)
      << out;
  EXPECT_EQ(line_count(out), 1) << out;
}

TEST(NodeCheckConfig, AcceptsReplayCamerasAndNamesThem) {
  TempDir dir("node_check_ok");
  const std::string rec = MOCAP_TEST_NODE_RECORDING;
  write_file(dir.file("node.yaml"),
             "node: {name: n1, domain_id: 7, detect_threads: 2}\ncameras:\n  - {backend: replay, "
             "device: " +
                 rec + ", camera: cam5, trigger: central}\n  - {backend: replay, device: " + rec +
                 ", camera: cam6, trigger: central}\n");
  int rc = -1;
  const std::string out = check(dir.file("node.yaml"), rc);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out, dir.file("node.yaml") +
                     ": OK (node n1, 2 replay cameras: cam5 cam6; 2 with trigger central; DDS "
                     "domain 7)\n");
}

// Each bad configuration: exit 1, one line "mocap: FILE: KEY...: PROBLEM".
TEST(NodeCheckConfig, RejectsBadInputWithOneLineNamingFileAndKey) {
  TempDir dir("node_check_bad");
  const std::string rec = MOCAP_TEST_NODE_RECORDING;
  struct Case {
    const char* name;
    std::string yaml;
    std::string expected;  // after "mocap: FILE: "
  };
  const Case cases[] = {
      {"unknown_key.yaml", "node: {nme: a}\ncameras:\n  - {backend: v4l2, device: /dev/video0}\n",
       "node.nme: unknown key (line 1)"},
      {"sim.yaml", "cameras:\n  - {backend: sim}\n",
       "cameras[0].backend: sim cameras are not supported on a node (replay or v4l2)"},
      {"size.yaml", "cameras:\n  - {backend: v4l2, device: /dev/video0}\n",
       "cameras[0].width: a node's v4l2 camera needs width and height"},
      {"no_camera.yaml", "cameras:\n  - {backend: replay, device: " + rec + ", camera: cam9}\n",
       "cameras[0].camera: the recording has no camera 'cam9' (it has cam0, cam1"},
      {"twice.yaml",
       "cameras:\n  - {backend: replay, device: " + rec +
           ", camera: cam2}\n  - {backend: replay, device: " + rec + ", camera: cam2}\n",
       "cameras[1]: publishes camera 'cam2' as cameras[0] does"},
      {"nine.yaml",
       "cameras:\n" +
           [] {
             std::string list;
             for (int c = 0; c < 9; ++c)
               list += "  - {backend: v4l2, device: /dev/video" + std::to_string(c) +
                       ", width: 640, height: 480}\n";
             return list;
           }(),
       "cameras: 9 cameras, at most 8 (line 2)"},
      {"workers.yaml",
       "node: {detect_threads: 2}\ncameras:\n  - {backend: replay, device: " + rec +
           ", camera: cam1, trigger: central}\n  - {backend: replay, device: " + rec +
           ", camera: cam2}\n",
       "node.detect_threads: 2 workers for 1 cameras with trigger: central (at most one per "
       "camera)"},
      {"workers_none.yaml",
       "node: {detect_threads: 1}\ncameras:\n  - {backend: v4l2, device: /dev/video0, width: "
       "640, height: 480}\n",
       "node.detect_threads: no camera has trigger: central (the workers serve those cameras)"},
      {"workers_zero.yaml",
       "node: {detect_threads: 0}\ncameras:\n  - {backend: replay, device: " + rec +
           ", camera: cam1, trigger: central}\n",
       "node.detect_threads: must be in [1, 8], got 0"},
      {"lead.yaml",
       "node: {trigger_lead_us: 200000}\ncameras:\n  - {backend: replay, device: " + rec +
           ", camera: cam1, trigger: central}\n",
       "node.trigger_lead_us: must be in [0, 100000], got 200000"},
      {"no_recording.yaml",
       "cameras:\n  - {backend: replay, device: " + dir.file("nothing") + "}\n",
       "cameras[0].device: "},
  };
  for (const Case& c : cases) {
    write_file(dir.file(c.name), c.yaml);
    int rc = -1;
    const std::string out = check(dir.file(c.name), rc);
    EXPECT_EQ(rc, 1) << c.name << ": " << out;
    EXPECT_EQ(out.rfind("mocap: " + dir.file(c.name) + ": " + c.expected, 0), 0u)
        << c.name << ": " << out;
    EXPECT_EQ(line_count(out), 1) << c.name << ": " << out;
  }
}

}  // namespace
}  // namespace mocap::test
