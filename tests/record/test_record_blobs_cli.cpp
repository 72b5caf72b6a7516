// `mocap record --blobs` end to end (runs the built `mocap`): a lockstep replay of an image
// recording recorded as blobs tracks to the same poses, points and labelled markers as
// the image recording (the acceptance, on a small 2-camera recording); kept images
// are the source's images; calibrate reads the blob recording; bad flags and a full disk
// end with one line and leave a valid recording.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <thread>

#include "formats/recording.h"
#include "tests/support/test_support.h"

namespace mocap::test {
namespace {

namespace fs = std::filesystem;

class RecordBlobsCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    src_dir_ = new TempDir("recb_src");
    // 30 loop frames of the built-in simulated cameras (2 x 1032x776).
    const RunResult r = run_mocap("record --out " + source() +
                                      " --frames 30 --loop-frames 30 --no-realtime "
                                      "--progress-interval 0",
                                  120);
    src_ok_ = r.exit_code == 0;
    src_log_ = r.output;
  }
  static void TearDownTestSuite() {
    delete src_dir_;
    src_dir_ = nullptr;
  }
  static std::string source() { return src_dir_->file("rec"); }
  // A lockstep replay of the source as a run configuration.
  static std::string replay_config(const TempDir& dir) {
    const std::string cfg = dir.file("replay.yaml");
    std::string cams;
    for (int c = 0; c < 2; ++c)
      cams += "  - {backend: replay, device: " + source() + ", trigger: software}\n";
    write_file(cfg, "cameras:\n" + cams + "targets: " + source() +
                        "/targets.yaml\nmodel: " + source() +
                        "/model.yaml\n"
                        "pipeline: {pacing: lockstep, realtime: false, lock_memory: false}\n"
                        "outputs: {udp: [], iceoryx: false}\n");
    return cfg;
  }
  static TempDir* src_dir_;
  static bool src_ok_;
  static std::string src_log_;
};
TempDir* RecordBlobsCli::src_dir_ = nullptr;
bool RecordBlobsCli::src_ok_ = false;
std::string RecordBlobsCli::src_log_;

TEST_F(RecordBlobsCli, BlobRecordingOfALockstepReplayTracksToTheSamePoses) {
  ASSERT_TRUE(src_ok_) << src_log_;
  TempDir dir("recb_same");
  const std::string blobs = dir.file("blobs_rec");
  const RunResult r = run_mocap("record --blobs --keep-images 10 --config " + replay_config(dir) +
                                    " --out " + blobs + " --progress-interval 0",
                                120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("30 frames (60 blob lists, 6 kept images"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("dropped blob lists: cam0 0, cam1 0 (writer behind); frames the "
                          "pipeline did not detect: 0"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(read_file(blobs + "/frames.csv"), read_file(source() + "/frames.csv"));
  EXPECT_TRUE(fs::exists(blobs + "/blobs/cam0.blobs"));
  EXPECT_TRUE(fs::exists(blobs + "/blobs/cam1.blobs"));
  // Every 10th frame's images kept, byte for byte the source's.
  for (const char* cam : {"cam0", "cam1"}) {
    EXPECT_EQ(std::distance(fs::directory_iterator(blobs + "/" + cam), fs::directory_iterator()),
              3);
    for (const char* f : {"000000.pgm", "000010.pgm", "000020.pgm"}) {
      const std::string rel = std::string("/") + cam + "/" + f;
      EXPECT_TRUE(read_file(blobs + rel) == read_file(source() + rel)) << rel;
    }
  }
  // The same poses, points and labelled markers as from the images.
  const std::string targets =
      " --targets " + source() + "/targets.yaml --model " + source() + "/model.yaml";
  const RunResult ti = run_mocap("track " + source() + targets + " --out " + dir.file("ti"), 120);
  ASSERT_EQ(ti.exit_code, 0) << ti.output;
  const RunResult tb = run_mocap("track " + blobs + targets + " --out " + dir.file("tb"), 120);
  ASSERT_EQ(tb.exit_code, 0) << tb.output;
  for (const char* f : {"poses.csv", "points.csv", "markers.csv", "angles.csv"}) {
    const std::string a = read_file(dir.file("ti/") + f), b = read_file(dir.file("tb/") + f);
    EXPECT_GT(line_count(a), 10) << f;
    EXPECT_TRUE(a == b) << f << " differs between the image and the blob recording";
  }
  // A torn tail (a crash while writing): one warning line, the frames before it tracked,
  // the last frame of that camera dropped.
  fs::copy(blobs, dir.file("torn"), fs::copy_options::recursive);
  const std::string cam1 = dir.file("torn/blobs/cam1.blobs");
  fs::resize_file(cam1, fs::file_size(cam1) - 7);
  const RunResult tt =
      run_mocap("track " + dir.file("torn") + targets + " --out " + dir.file("tt"), 120);
  EXPECT_EQ(tt.exit_code, 0) << tt.output;
  EXPECT_NE(tt.output.find("cam1.blobs: torn tail at byte offset"), std::string::npos) << tt.output;
  EXPECT_NE(tt.output.find("tracked 30 frames (1 with a missing camera frame, 0 damaged)"),
            std::string::npos)
      << tt.output;
  // calibrate reads it too, to the same model.
  const std::string joints = source() + "/joints.yaml";
  if (fs::exists(joints)) {
    const std::string c = " --targets " + source() + "/targets.yaml --joints " + joints;
    const RunResult ci =
        run_mocap("calibrate " + source() + c + " --out " + dir.file("mi.yaml"), 120);
    const RunResult cb = run_mocap("calibrate " + blobs + c + " --out " + dir.file("mb.yaml"), 120);
    EXPECT_EQ(ci.exit_code, cb.exit_code) << ci.output << cb.output;
    EXPECT_TRUE(read_file(dir.file("mi.yaml")) == read_file(dir.file("mb.yaml")));
  }
  // discover finds the same bodies in both.
  const RunResult di = run_mocap("discover " + source() + " --out " + dir.file("di"), 120);
  const RunResult db = run_mocap("discover " + blobs + " --out " + dir.file("db"), 120);
  EXPECT_EQ(di.exit_code, db.exit_code) << di.output << db.output;
  EXPECT_GT(line_count(read_file(dir.file("di/targets.yaml"))), 5);
  EXPECT_TRUE(read_file(dir.file("di/targets.yaml")) == read_file(dir.file("db/targets.yaml")));
  // A replay camera cannot play a blob recording: one line.
  const std::string bad_cfg = dir.file("replay_blobs.yaml");
  write_file(bad_cfg, "cameras:\n  - {backend: replay, device: " + blobs +
                          "}\n  - {backend: replay, device: " + blobs +
                          "}\noutputs: {udp: [], iceoryx: false}\n");
  const RunResult rb =
      run_mocap("record --config " + bad_cfg + " --out " + dir.file("x") + " --frames 2", 60);
  EXPECT_EQ(rb.exit_code, 2) << rb.output;
  EXPECT_EQ(line_count(rb.output), 1) << rb.output;
  EXPECT_NE(rb.output.find("a blob recording holds blob lists, not images"), std::string::npos)
      << rb.output;
}

// calibrate-rig reads a blob recording of a wand: the recorded centroids, no edge fits
// (one note line), a rig close to the true one.
TEST_F(RecordBlobsCli, CalibrateRigReadsAWandBlobRecording) {
  TempDir dir("recb_wand");
  const std::string wand = dir.file("wand");
  const RunResult sim =
      run_mocap("simulate --out " + wand + " --motion wand --frames 300 --seed 3", 120);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string cfg = dir.file("replay_wand.yaml");
  write_file(cfg, "cameras:\n  - {backend: replay, device: " + wand +
                      ", trigger: software}\n  - {backend: replay, device: " + wand +
                      ", trigger: software}\npipeline: {pacing: lockstep, realtime: false, "
                      "lock_memory: false}\noutputs: {udp: [], iceoryx: false}\n");
  const std::string blobs = dir.file("wand_blobs");
  const RunResult rec = run_mocap(
      "record --blobs --config " + cfg + " --out " + blobs + " --progress-interval 0", 120);
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  EXPECT_NE(rec.output.find("300 frames (600 blob lists"), std::string::npos) << rec.output;
  const RunResult cal = run_mocap(
      "calibrate-rig " + blobs + " --wand " + wand + "/wand.yaml --out " + dir.file("rig.yaml"),
      120);
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  EXPECT_NE(cal.output.find("note: " + blobs +
                            ": a blob recording: the balls' centres are the "
                            "recorded blob centroids"),
            std::string::npos)
      << cal.output;
  // The simulated rig's baseline is 477 mm (docs/rig_calibration.md).
  const std::size_t at = cal.output.find("baseline ");
  ASSERT_NE(at, std::string::npos) << cal.output;
  EXPECT_NEAR(std::stod(cal.output.substr(at + 9)), 477.0, 0.5) << cal.output;
}

TEST_F(RecordBlobsCli, BadFlagsAreOneLineErrors) {
  TempDir dir("recb_bad");
  struct Case {
    std::string args, needle;
  };
  const Case cases[] = {
      {"record --out " + dir.file("a") + " --frames 3 --keep-images 5", "only with --blobs"},
      {"record --blobs --out " + dir.file("a") + " --frames 3 --keep-images 0", "must be 1.."},
  };
  for (const Case& c : cases) {
    const RunResult r = run_mocap(c.args, 30);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_EQ(line_count(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.needle), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir.file("a")));
}

TEST_F(RecordBlobsCli, FullDiskEndsWithOneLineAndTheFramesBeforeStayReadable) {
  TempDir dir("recb_full");
  const std::string out = dir.file("rec");
  const pid_t pid = fork();
  if (pid == 0) {  // RLIMIT_FSIZE: a write past 3000 bytes fails with EFBIG, as a full disk
    if (std::freopen(dir.file("log").c_str(), "w", stdout) == nullptr) _exit(126);
    dup2(fileno(stdout), STDERR_FILENO);
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit lim{3000, 3000};
    setrlimit(RLIMIT_FSIZE, &lim);
    const std::string bin = mocap_binary();
    execl(bin.c_str(), bin.c_str(), "record", "--blobs", "--out", out.c_str(), "--frames", "200",
          "--loop-frames", "10", "--no-realtime", "--progress-interval", "0",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  for (int i = 0; i < 6000 && waitpid(pid, &status, WNOHANG) != pid; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::string log = read_file(dir.file("log"));
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 1) << log;
  EXPECT_NE(log.find(".blobs: cannot write frame"), std::string::npos) << log;
  EXPECT_NE(log.find("File too large"), std::string::npos) << log;
  auto rec = Recording::open(out);
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  EXPECT_TRUE(rec->has_blobs());
  EXPECT_TRUE(rec->warnings().empty()) << rec->warnings().front();  // cut back to whole chunks
  EXPECT_GE(rec->frames().size(), 1u);
  detect::BlobList list(512);
  std::vector<std::uint8_t> scratch;
  for (const FrameEntry& f : rec->frames())  // every frame listed has its blob lists
    for (int c = 0; c < 2; ++c)
      EXPECT_EQ(*rec->load_blobs(c, f.frame, list, scratch), FrameLoad::kOk);
}

}  // namespace
}  // namespace mocap::test
