// Design: small helpers shared by the tests: temporary folders, file reading and
// writing, counting lines, the path of the built `mocap` binary, and running it (or
// any shell command, optionally under a time limit) to capture its exit code and
// output.
#pragma once

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace mocap::test {

// A fresh, empty temporary folder (removed at destruction).
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    std::string templ =
        (std::filesystem::temp_directory_path() / ("mocap_" + tag + "_XXXXXX")).string();
    char* p = mkdtemp(templ.data());
    path_ = p ? std::string(p) : std::string();
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

inline void write_file(const std::string& path, const std::string& content) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream f(path, std::ios::binary);
  f << content;
}

inline std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// The number of '\n' in text (the lines of a program's output or of a CSV file).
inline int line_count(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

#ifndef MOCAP_TEST_SOURCE_DIR
#define MOCAP_TEST_SOURCE_DIR "."
#endif
#ifndef MOCAP_TEST_BINARY_DIR
#define MOCAP_TEST_BINARY_DIR "."
#endif

// The source tree ($MOCAP_SOURCE_DIR, else the configured one).
inline std::string source_dir() {
  const char* s = std::getenv("MOCAP_SOURCE_DIR");
  return s ? s : MOCAP_TEST_SOURCE_DIR;
}

// The built `mocap` ($MOCAP_BINARY_DIR/mocap, else the configured build tree's).
inline std::string mocap_binary() {
  const char* b = std::getenv("MOCAP_BINARY_DIR");
  return std::string(b ? b : MOCAP_TEST_BINARY_DIR) + "/mocap";
}

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, capturing stdout+stderr (append " 2>&1" to cmd to get
// stderr too). exit_code -1 when it could not run or did not exit normally (signal).
inline RunResult run_command(const std::string& cmd) {
  RunResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs `mocap <args>` through the shell, capturing stdout+stderr. timeout_s > 0 runs it
// under `timeout -s KILL <timeout_s>`, so that a hang fails the test (exit 137) instead
// of stalling CI.
inline RunResult run_mocap(const std::string& args, int timeout_s = 0) {
  const std::string prefix =
      timeout_s > 0 ? "timeout -s KILL " + std::to_string(timeout_s) + " " : std::string();
  return run_command(prefix + mocap_binary() + " " + args + " 2>&1");
}

}  // namespace mocap::test
