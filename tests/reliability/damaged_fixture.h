// Design: shared set-up of the damaged-recording tests. One small simulated recording
// (a few frames of the built-in scenario, rendered once per ctest run) is copied into
// a fresh folder per test, damaged there, and `mocap track` is run on it under
// `timeout` so that a hang fails the test instead of stalling CI. The outcome must be
// one of the two the developers' rules allow: exit 0 having processed what it could
// (with a warning naming the damaged file), or exit 2 with ONE line naming the file.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "formats/pgm.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::test {

#ifndef MOCAP_TEST_PRISTINE_FRAMES
#define MOCAP_TEST_PRISTINE_FRAMES 6
#endif
inline constexpr int kDamagedFrames = MOCAP_TEST_PRISTINE_FRAMES;

// The pristine recording (never modified): the one ctest's fixture rendered for this run
// (tests/reliability/CMakeLists.txt), or, when the binary runs on its own, one rendered
// here once per process.
inline const std::string& pristine_recording() {
  static std::unique_ptr<TempDir> dir;
  static std::string path;
  if (!path.empty()) return path;
#ifdef MOCAP_TEST_PRISTINE_RECORDING
  namespace fs = std::filesystem;
  const std::string fixture = MOCAP_TEST_PRISTINE_RECORDING;
  if (fs::exists(fixture + "/frames.csv") && fs::exists(fixture + "/gt/model_true.yaml") &&
      std::max(0, line_count(read_file(fixture + "/frames.csv")) - 1) == kDamagedFrames) {
    path = fixture;
    return path;
  }
#endif
  dir = std::make_unique<TempDir>("reliability_src");
  sim::SimOptions o;
  o.frames = kDamagedFrames;
  o.threads = 1;
  path = dir->path() + "/rec";
  auto r = sim::write_simulated_recording(o, path);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return path;
}

// A private, writable copy of the recording: rec/ (rig.yaml, frames.csv, cam0, cam1),
// targets.yaml and model.yaml next to it, out/ for the outputs.
class DamagedRecording {
 public:
  explicit DamagedRecording(const std::string& tag) : tmp_(tag) {
    namespace fs = std::filesystem;
    const std::string src = pristine_recording();
    fs::create_directories(rec());
    for (const char* f : {"rig.yaml", "frames.csv"}) fs::copy_file(src + "/" + f, rec() + "/" + f);
    for (const char* c : {"cam0", "cam1"})
      fs::copy(src + "/" + c, rec() + "/" + c, fs::copy_options::recursive);
    fs::copy_file(src + "/targets.yaml", targets());
    fs::copy_file(src + "/gt/model_true.yaml", model());
  }
  std::string rec() const { return tmp_.file("rec"); }
  std::string targets() const { return tmp_.file("targets.yaml"); }
  std::string model() const { return tmp_.file("model.yaml"); }
  std::string out() const { return tmp_.file("out"); }
  std::string frame(int camera, int index) const {
    char name[32];
    std::snprintf(name, sizeof name, "/cam%d/%06d.pgm", camera, index);
    return rec() + name;
  }
  std::string tmp(const std::string& name) const { return tmp_.file(name); }

  // `mocap track` with the model (angles too), bounded in time.
  RunResult track(const std::string& extra = "") const {
    return run_bounded("track " + rec() + " --targets " + targets() + " --model " + model() +
                       " --out " + out() + " --stats " + out() + "/stats.json --quiet " + extra);
  }

  // Runs `mocap <args>` under `timeout` (a hang is exit 124 or 137).
  static RunResult run_bounded(const std::string& args, int seconds = 30) {
    return run_mocap(args, seconds);
  }

 private:
  TempDir tmp_;
};

inline std::string file_name(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// Exit 2 with exactly one line that names `path` (its file name at least).
inline ::testing::AssertionResult is_one_line_error(const RunResult& r, const std::string& path) {
  if (r.exit_code != 2 || line_count(r.output) != 1 ||
      r.output.find(file_name(path)) == std::string::npos || r.output.rfind("mocap: ", 0) != 0) {
    return ::testing::AssertionFailure() << "expected a one-line error naming " << file_name(path)
                                         << ", got exit " << r.exit_code << ":\n"
                                         << r.output;
  }
  return ::testing::AssertionSuccess();
}

// Exit 0, every output line a warning, one of them naming `path`.
inline ::testing::AssertionResult is_warned_success(const RunResult& r, const std::string& path) {
  bool named = false, only_warnings = true;
  std::size_t begin = 0;
  while (begin < r.output.size()) {
    std::size_t end = r.output.find('\n', begin);
    if (end == std::string::npos) end = r.output.size();
    const std::string line = r.output.substr(begin, end - begin);
    if (line.rfind("mocap: warning: ", 0) != 0) only_warnings = false;
    if (line.find(path) != std::string::npos) named = true;
    begin = end + 1;
  }
  if (r.exit_code != 0 || !named || !only_warnings) {
    return ::testing::AssertionFailure() << "expected success with a warning naming " << path
                                         << ", got exit " << r.exit_code << ":\n"
                                         << r.output;
  }
  return ::testing::AssertionSuccess();
}

// Rows of a CSV file after its header.
inline int csv_rows(const std::string& path) {
  return std::max(0, line_count(read_file(path)) - 1);
}

// Distinct frame numbers (first column) of a CSV file.
inline std::vector<long> csv_frames(const std::string& path) {
  std::vector<long> frames;
  const std::string text = read_file(path);
  std::size_t pos = text.find('\n');
  while (pos != std::string::npos && pos + 1 < text.size()) {
    const long f = std::strtol(text.c_str() + pos + 1, nullptr, 10);
    if (frames.empty() || frames.back() != f) frames.push_back(f);
    pos = text.find('\n', pos + 1);
  }
  return frames;
}

// Writes an 8-bit PGM of the given size whose pixels come from fn(x, y).
template <class F>
void write_pgm8(const std::string& path, int width, int height, F&& fn) {
  Image img(width, height, PixelFormat::kMono8, 255);
  for (int y = 0; y < height; ++y) {
    std::uint8_t* row = img.row8(y);
    for (int x = 0; x < width; ++x) row[x] = fn(x, y);
  }
  auto r = write_pgm(path, img.view());
  ASSERT_TRUE(r.ok()) << r.error().message;
}

}  // namespace mocap::test
