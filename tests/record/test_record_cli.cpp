// End-to-end tests of `mocap record` on the built-in simulated cameras and on a lockstep
// replay (also a master with an external-triggered slave): bad input, a recording `mocap
// track` reads, byte-identical re-recording, a
// file-size limit (the full-disk path with a real EFBIG), an unwritable folder and a
// stop signal mid-recording. Each run uses a 10-frame sim loop to stay fast.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#include "formats/csv_outputs.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "tests/support/test_support.h"

namespace mocap::test {
namespace {

namespace fs = std::filesystem;

// Non-empty lines of a command's output that start with "mocap: " (the error lines).
int error_lines(const std::string& out) {
  int n = 0;
  std::size_t pos = 0;
  while ((pos = out.find("mocap: ", pos)) != std::string::npos) {
    if (pos == 0 || out[pos - 1] == '\n') ++n;
    pos += 7;
  }
  return n;
}

// Every row of frames.csv has its files (unless missing), and every file has a row; no
// temporary file is left.
void expect_consistent(const std::string& dir, std::size_t* rows = nullptr) {
  auto rec = Recording::open(dir);
  ASSERT_TRUE(rec) << rec.error().message;
  std::set<std::string> listed;
  for (const FrameEntry& e : rec->frames())
    for (const CameraModel& cam : rec->rig().cameras)
      listed.insert(frame_file_path(dir, cam.name, e.frame));
  for (const CameraModel& cam : rec->rig().cameras) {
    for (const auto& f : fs::directory_iterator(dir + "/" + cam.name)) {
      EXPECT_EQ(f.path().extension(), ".pgm") << f.path();
      EXPECT_TRUE(listed.count(f.path().string())) << f.path() << " has no row";
    }
  }
  if (rows) *rows = rec->frames().size();
}

class RecordCli : public ::testing::Test {
 protected:
  // One default sim recording for the tests that read one (rendering is the slow part),
  // made on first use: ctest runs every test in a process of its own.
  static void make_source() {
    if (source_ != nullptr) return;
    source_ = new TempDir("rec_src");
    // 30 loop frames: the default scene shows the lower arm in a few of them.
    const RunResult r = run_mocap("record --out " + source_->file("rec") +
                                      " --frames 30 --loop-frames 30 --no-realtime "
                                      "--progress-interval 0",
                                  120);
    source_ok_ = r.exit_code == 0;
    source_log_ = r.output;
  }
  static void TearDownTestSuite() {
    delete source_;
    source_ = nullptr;
  }
  static std::string source() { return source_->file("rec"); }
  static TempDir* source_;
  static bool source_ok_;
  static std::string source_log_;
};
TempDir* RecordCli::source_ = nullptr;
bool RecordCli::source_ok_ = false;
std::string RecordCli::source_log_;

TEST_F(RecordCli, BadInputIsOneLineError) {
  TempDir dir("rec_bad");
  struct Case {
    std::string args, needle;
  };
  test::write_file(dir.file("full/x.txt"), "x");
  const Case cases[] = {
      {"record --out " + dir.file("a") + " --frames 0", "--frames: must be >= 1"},
      {"record --out " + dir.file("a") + " --frames 3 --duration 1", "not both"},
      {"record --out " + dir.file("a") + " --duration 0", "--duration: must be > 0"},
      {"record --frames 3", "--out"},
      {"record --out " + dir.file("full") + " --frames 3", "not empty"},
      {"record --out " + dir.file("full/x.txt") + " --frames 3", "not a folder"},
      {"record --config " + dir.file("none.yaml") + " --out " + dir.file("a"), "none.yaml"},
      {"record --out /proc/mocap_no/rec --frames 3", "cannot create"},
  };
  for (const Case& c : cases) {
    const RunResult r = run_mocap(c.args, 30);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_EQ(line_count(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.needle), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir.file("a")));  // nothing created on bad input
}

TEST_F(RecordCli, SimRecordingIsReadByTrackAndItsBodiesAreFound) {
  make_source();
  ASSERT_TRUE(source_ok_) << source_log_;
  EXPECT_NE(source_log_.find("30 frames (60 images"), std::string::npos) << source_log_;
  std::size_t rows = 0;
  expect_consistent(source(), &rows);
  EXPECT_EQ(rows, 30u);
  for (const char* f : {"rig.yaml", "targets.yaml", "model.yaml", "joints.yaml"})
    EXPECT_TRUE(fs::exists(source() + "/" + f)) << f;
  TempDir out("rec_track");
  const RunResult t =
      run_mocap("track " + source() + " --targets " + source() + "/targets.yaml --model " +
                    source() + "/model.yaml --out " + out.path(),
                120);
  ASSERT_EQ(t.exit_code, 0) << t.output;
  auto targets = load_targets(source() + "/targets.yaml");
  ASSERT_TRUE(targets);
  auto poses = read_poses_csv(out.file("poses.csv"));
  ASSERT_TRUE(poses) << poses.error().message;
  // Every body is found (the lower arm is often hidden in the scene's first frames), the
  // torso in almost every frame.
  std::map<std::string, std::size_t> found;
  for (const PoseRow& p : *poses) ++found[p.body];
  for (const auto& body : targets->bodies) EXPECT_GE(found[body.name], 1u) << body.name;
  EXPECT_GE(found["torso"], rows * 9 / 10);
  EXPECT_TRUE(fs::exists(out.file("angles.csv")));
}

// Records the source through two replay cameras with the given triggers and pacing and
// checks the copy: every frame of the source, image for image, byte-identical.
void expect_replay_recorded_whole(const std::string& source, const std::string& trigger1,
                                  const std::string& pacing) {
  TempDir dir("rec_replay");
  const std::string cfg = dir.file("replay.yaml");
  write_file(cfg,
             "cameras:\n"
             "  - {backend: replay, device: " +
                 source +
                 ", trigger: software}\n"
                 "  - {backend: replay, device: " +
                 source + ", trigger: " + trigger1 +
                 "}\n"
                 "targets: " +
                 source +
                 "/targets.yaml\n"
                 "model: " +
                 source +
                 "/model.yaml\n"
                 "pipeline: {pacing: " +
                 pacing +
                 ", realtime: false, lock_memory: false}\n"
                 "outputs: {udp: [], iceoryx: false}\n");
  const std::string copy = dir.file("copy");
  const RunResult r =
      run_mocap("record --config " + cfg + " --out " + copy + " --progress-interval 0", 120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_file(copy + "/frames.csv"), read_file(source + "/frames.csv"));
  int files = 0;
  for (const char* cam : {"cam0", "cam1"}) {
    for (const auto& f : fs::directory_iterator(source + "/" + cam)) {
      const std::string name = f.path().filename().string();
      ASSERT_TRUE(fs::exists(copy + "/" + cam + "/" + name)) << name;
      EXPECT_TRUE(read_file(f.path().string()) == read_file(copy + "/" + cam + "/" + name))
          << cam << "/" << name << " differs";
      ++files;
    }
    EXPECT_EQ(std::distance(fs::directory_iterator(copy + "/" + cam), fs::directory_iterator()),
              std::distance(fs::directory_iterator(source + "/" + cam), fs::directory_iterator()));
  }
  EXPECT_GE(files, 50);
  EXPECT_NE(r.output.find("30 frames (60 images"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("dropped images: cam0 0, cam1 0"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("30 frames triggered, 30 written, 0 not written; frames written "
                          "without a camera's image: cam0 0, cam1 0"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  // The configuration's files are copied byte for byte.
  EXPECT_EQ(read_file(copy + "/model.yaml"), read_file(source + "/model.yaml"));
  EXPECT_EQ(read_file(copy + "/targets.yaml"), read_file(source + "/targets.yaml"));
  if (trigger1 == "external") {
    EXPECT_NE(r.output.find("cam1: trigger: external in a replay follows"), std::string::npos)
        << r.output;
  }
}

TEST_F(RecordCli, LockstepReplayIsRecordedAgainByteIdentical) {
  make_source();
  ASSERT_TRUE(source_ok_) << source_log_;
  expect_replay_recorded_whole(source(), "software", "lockstep");
}

// A master (software trigger) and an external-triggered slave, as a lab wires them: the
// slave follows the master's triggers, in lockstep and at the trigger rate alike (until
// 2026-12-07 the slave free-ran and the master recorded a frame a second, silently).
TEST_F(RecordCli, MasterAndExternalSlaveReplayIsRecordedFrameForFrame) {
  make_source();
  ASSERT_TRUE(source_ok_) << source_log_;
  {
    SCOPED_TRACE("lockstep");
    expect_replay_recorded_whole(source(), "external", "lockstep");
  }
  {
    SCOPED_TRACE("periodic");
    expect_replay_recorded_whole(source(), "external", "periodic");
  }
}

// A frame a camera did not deliver (here: the replay's file is missing) is counted in the
// final line and warned about, never silently absent.
TEST_F(RecordCli, AMissingImageIsCountedAndWarned) {
  make_source();
  ASSERT_TRUE(source_ok_) << source_log_;
  TempDir dir("rec_missing");
  const std::string src = dir.file("src");
  fs::copy(source(), src, fs::copy_options::recursive);
  ASSERT_TRUE(fs::remove(src + "/cam1/000007.pgm"));
  write_file(dir.file("replay.yaml"),
             "cameras:\n"
             "  - {backend: replay, device: " +
                 src +
                 ", trigger: software}\n"
                 "  - {backend: replay, device: " +
                 src +
                 ", trigger: software}\n"
                 "pipeline: {pacing: lockstep, realtime: false, lock_memory: false}\n"
                 "outputs: {udp: [], iceoryx: false}\n");
  const RunResult r = run_mocap("record --config " + dir.file("replay.yaml") + " --out " +
                                    dir.file("copy") + " --progress-interval 0",
                                120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("30 frames triggered, 30 written, 0 not written; frames written "
                          "without a camera's image: cam0 0, cam1 1"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("warning: 0 triggered frames were not written and 1 camera images"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir.file("copy") + "/cam1/000007.pgm"));
}

// Runs mocap with stdout+stderr into `log`; optional RLIMIT_FSIZE (SIGXFSZ ignored, so a
// write past the limit fails with EFBIG as on a full disk).
pid_t spawn_mocap(const std::vector<std::string>& args, const std::string& log,
                  rlim_t fsize_limit = RLIM_INFINITY) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  if (std::freopen(log.c_str(), "w", stdout) == nullptr) _exit(126);
  dup2(fileno(stdout), STDERR_FILENO);
  std::signal(SIGXFSZ, SIG_IGN);
  const rlimit lim{fsize_limit, fsize_limit};
  if (fsize_limit != RLIM_INFINITY) setrlimit(RLIMIT_FSIZE, &lim);
  std::vector<char*> argv;
  const std::string bin = mocap_binary();
  argv.push_back(const_cast<char*>(bin.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(bin.c_str(), argv.data());
  _exit(127);
}

int wait_exit(pid_t pid, int timeout_s) {
  for (int i = 0; i < timeout_s * 50; ++i) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -2;
}

TEST_F(RecordCli, FileSizeLimitEndsWithOneLineErrorAndAValidFolder) {
  TempDir dir("rec_fsize");
  const std::string out = dir.file("rec");
  // 1032x776 images (800 kB) do not fit a 500 kB file-size limit: the first PGM fails.
  const pid_t pid = spawn_mocap({"record", "--out", out, "--frames", "20", "--loop-frames", "10",
                                 "--no-realtime", "--progress-interval", "0"},
                                dir.file("log"), 500'000);
  const int code = wait_exit(pid, 120);
  const std::string log = read_file(dir.file("log"));
  EXPECT_EQ(code, 1) << log;
  EXPECT_EQ(error_lines(log), 1) << log;
  EXPECT_NE(log.find("cam0/000000.pgm: cannot write: File too large"), std::string::npos) << log;
  // Nothing half-written: the header only, no image and no temporary file.
  EXPECT_EQ(read_file(out + "/frames.csv"), "frame,timestamp_ns\n");
  for (const char* cam : {"cam0", "cam1"})
    EXPECT_EQ(std::distance(fs::directory_iterator(out + "/" + cam), fs::directory_iterator()), 0);
}

TEST_F(RecordCli, StopSignalMidRecordingLeavesAValidRecording) {
  TempDir dir("rec_sig");
  const std::string out = dir.file("rec");
  const pid_t pid = spawn_mocap(
      {"record", "--out", out, "--loop-frames", "10", "--no-realtime", "--progress-interval", "0"},
      dir.file("log"));
  // Wait until frames are being written, then stop it.
  bool writing = false;
  for (int i = 0; i < 3000 && !writing; ++i) {
    writing = line_count(read_file(out + "/frames.csv")) > 10;
    if (!writing) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(writing) << read_file(dir.file("log"));
  kill(pid, SIGTERM);
  const int code = wait_exit(pid, 60);
  const std::string log = read_file(dir.file("log"));
  EXPECT_EQ(code, 0) << log;
  EXPECT_NE(log.find("stopped by SIGTERM"), std::string::npos) << log;
  std::size_t rows = 0;
  expect_consistent(out, &rows);
  EXPECT_GT(rows, 10u);
}

}  // namespace
}  // namespace mocap::test
