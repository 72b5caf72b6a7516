// Design: the built `mocap run` under a fake service manager. The test binds an
// AF_UNIX datagram socket, starts mocap with NOTIFY_SOCKET pointing at it and
// WATCHDOG_USEC set (as systemd does for Type=notify + WatchdogSec=), and records every
// notification with its arrival time. Checks: READY=1 after start, WATCHDOG=1 at half
// the watchdog timeout while frames flow, no WATCHDOG=1 once the pipeline stalls (fault
// injection: camera 0 stops after N frames) although STATUS keeps coming (the process
// is alive), STOPPING=1 at the end, and SIGTERM ends the process within a second.
// A tiny replayed recording and no real-time scheduling keep each test short.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "tests/service/tiny_recording.h"
#include "tests/support/test_support.h"

extern char** environ;

namespace mocap::test {
namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

struct Note {
  std::string text;
  std::int64_t t_ns;
};

class FakeServiceManager {
 public:
  explicit FakeServiceManager(const std::string& path) : path_(path) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    path.copy(a.sun_path, sizeof a.sun_path - 1);
    bound_ = fd_ >= 0 && bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~FakeServiceManager() {
    if (fd_ >= 0) close(fd_);
  }
  bool ok() const { return bound_; }

  // Receives for up to timeout_ms; returns after the first batch.
  void receive(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return;
    char buf[4096];
    for (;;) {
      const ssize_t n = recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      // sd_notify may join several assignments with '\n' in one datagram.
      std::string all(buf, static_cast<std::size_t>(n));
      std::size_t start = 0;
      while (start < all.size()) {
        std::size_t end = all.find('\n', start);
        if (end == std::string::npos) end = all.size();
        notes.push_back({all.substr(start, end - start), now_ns()});
        start = end + 1;
      }
    }
  }
  int count(const std::string& s) const {
    int c = 0;
    for (const Note& n : notes) c += n.text == s ? 1 : 0;
    return c;
  }
  std::vector<Note> notes;

 private:
  std::string path_;
  int fd_ = -1;
  bool bound_ = false;
};

struct Child {
  pid_t pid = -1;
  int status = 0;
  bool exited = false;
};

Child spawn_mocap(const std::vector<std::string>& args, const std::vector<std::string>& env,
                  const std::string& log_path) {
  std::vector<std::string> argv_s = {mocap_binary()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string v(*e);
    if (v.rfind("NOTIFY_SOCKET=", 0) != 0 && v.rfind("WATCHDOG_", 0) != 0) env_s.push_back(v);
  }
  env_s.insert(env_s.end(), env.begin(), env.end());
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  Child c;
  if (posix_spawn(&c.pid, argv[0], &fa, nullptr, argv.data(), envp.data()) != 0) c.pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return c;
}

bool try_wait(Child& c) {
  if (c.exited) return true;
  if (waitpid(c.pid, &c.status, WNOHANG) == c.pid) c.exited = true;
  return c.exited;
}

// Runs the child to its end (or kills it after limit_ms), collecting notifications.
void collect_until_exit(FakeServiceManager& sm, Child& c, int limit_ms) {
  const std::int64_t deadline = now_ns() + std::int64_t{limit_ms} * 1'000'000;
  while (!try_wait(c) && now_ns() < deadline) sm.receive(10);
  if (!try_wait(c)) {
    kill(c.pid, SIGKILL);
    waitpid(c.pid, &c.status, 0);
    c.exited = true;
  }
  sm.receive(0);
}

std::string write_config(const TempDir& dir, const std::string& extra) {
  write_tiny_recording(dir.file("rec"), 300);  // 3 s at 100 Hz: longer than any test run
  const std::string path = dir.file("mocap.yaml");
  write_file(path, tiny_replay_config(dir.file("rec"), extra));
  return path;
}

std::string dump(const FakeServiceManager& sm, std::int64_t t0) {
  std::string s;
  for (const Note& n : sm.notes)
    s += std::to_string((n.t_ns - t0) / 1'000'000) + " ms: " + n.text + "\n";
  return s;
}

// `mocap run` on the tiny replay (config_extra appended to its configuration) for
// duration_s under the fake service manager with WATCHDOG_USEC=100000 (pings due
// every 50 ms), collected to its end (killed after 20 s).
struct WatchdogRun {
  explicit WatchdogRun(const std::string& tag) : dir(tag), sm(dir.file("notify.sock")) {}

  // False when the socket could not be bound or mocap not be started.
  bool run_to_end(const std::string& config_extra, const std::string& duration_s) {
    if (!sm.ok()) return false;
    const std::string cfg = write_config(dir, config_extra);
    t0 = now_ns();
    child = spawn_mocap({"run", "--config", cfg, "--duration", duration_s},
                        {"NOTIFY_SOCKET=" + dir.file("notify.sock"), "WATCHDOG_USEC=100000"},
                        dir.file("log.txt"));
    if (child.pid <= 0) return false;
    collect_until_exit(sm, child, 20000);
    return true;
  }
  bool exited_ok() const { return WIFEXITED(child.status) && WEXITSTATUS(child.status) == 0; }
  std::string log() const { return read_file(dir.file("log.txt")); }
  // Every notification with its time since the start, for failure messages.
  std::string trace() const { return dump(sm, t0); }

  TempDir dir;
  FakeServiceManager sm;
  std::int64_t t0 = 0;
  Child child;
};

TEST(ServiceProcess, ReadyThenWatchdogAtHalfTheTimeout) {
  WatchdogRun run("svc_notify");
  ASSERT_TRUE(run.run_to_end("", "0.8")) << "cannot bind the notify socket or start mocap";
  ASSERT_TRUE(run.exited_ok()) << run.log();
  const FakeServiceManager& sm = run.sm;
  const std::string trace = run.trace();
  ASSERT_EQ(sm.count("READY=1"), 1) << trace;
  ASSERT_EQ(sm.count("STOPPING=1"), 1) << trace;
  std::size_t ready = 0, stopping = 0;
  std::vector<std::int64_t> pings;
  for (std::size_t i = 0; i < sm.notes.size(); ++i) {
    const std::string& t = sm.notes[i].text;
    if (t == "READY=1") ready = i;
    if (t == "STOPPING=1") stopping = i;
    if (t == "WATCHDOG=1") {
      EXPECT_GT(i, ready) << "WATCHDOG before READY\n" << trace;
      pings.push_back(sm.notes[i].t_ns);
    }
  }
  EXPECT_GT(stopping, ready);
  // Half of WATCHDOG_USEC = 50 ms: never faster, and steadily while frames flow.
  ASSERT_GE(pings.size(), 5u) << trace;
  for (std::size_t i = 1; i < pings.size(); ++i)
    EXPECT_GE(pings[i] - pings[i - 1], 45'000'000) << trace;
  EXPECT_LT(sm.notes[stopping].t_ns - pings.back(), 400'000'000) << trace;
  bool status_with_stats = false;
  for (const Note& n : sm.notes)
    status_with_stats |=
        n.text.rfind("STATUS=", 0) == 0 && n.text.find(" fps, p99 ") != std::string::npos;
  EXPECT_TRUE(status_with_stats) << trace;
}

TEST(ServiceProcess, NoWatchdogOnceThePipelineStalls) {
  WatchdogRun run("svc_stall");
  ASSERT_TRUE(run.run_to_end("fault_injection: {stall_after_frames: 20}\n", "1.0"))
      << "cannot bind the notify socket or start mocap";
  const std::string log = run.log();
  ASSERT_TRUE(run.exited_ok()) << log;
  const FakeServiceManager& sm = run.sm;
  const std::int64_t t0 = run.t0;
  const std::string trace = run.trace();
  ASSERT_EQ(sm.count("READY=1"), 1) << trace;
  std::int64_t last_ping = 0, stopping = 0;
  for (const Note& n : sm.notes) {
    if (n.text == "WATCHDOG=1") last_ping = n.t_ns;
    if (n.text == "STOPPING=1") stopping = n.t_ns;
  }
  ASSERT_GT(stopping, 0) << trace;
  // 20 frames at 100 Hz: the stall starts ~0.2 s after READY; the run lasts 1.0 s.
  const std::int64_t silent_from = last_ping > 0 ? last_ping : t0;
  EXPECT_GE(stopping - silent_from, 500'000'000) << trace;
  // ...while the process was alive and reporting the stall.
  int stalled_status = 0;
  for (const Note& n : sm.notes)
    stalled_status += n.t_ns > silent_from && n.text.rfind("STATUS=STALLED", 0) == 0 ? 1 : 0;
  EXPECT_GE(stalled_status, 3) << trace;
  EXPECT_NE(log.find("pipeline stalled"), std::string::npos) << log;
}

TEST(ServiceProcess, SigtermStopsWithinOneSecond) {
  TempDir dir("svc_term");
  FakeServiceManager sm(dir.file("notify.sock"));
  ASSERT_TRUE(sm.ok());
  const std::string cfg = write_config(dir, "");
  Child c = spawn_mocap({"run", "--config", cfg}, {"NOTIFY_SOCKET=" + dir.file("notify.sock")},
                        dir.file("log.txt"));
  ASSERT_GT(c.pid, 0);
  const std::int64_t limit = now_ns() + 20'000'000'000;
  while (sm.count("READY=1") == 0 && !try_wait(c) && now_ns() < limit) sm.receive(20);
  ASSERT_EQ(sm.count("READY=1"), 1) << read_file(dir.file("log.txt"));
  const std::int64_t t_term = now_ns();
  ASSERT_EQ(kill(c.pid, SIGTERM), 0);
  while (!try_wait(c) && now_ns() - t_term < 5'000'000'000) usleep(2000);
  const std::int64_t took_ns = now_ns() - t_term;
  if (!c.exited) {
    kill(c.pid, SIGKILL);
    waitpid(c.pid, &c.status, 0);
  }
  // The requirement of the service (TimeoutStopSec is far longer): clean exit within 1 s.
  EXPECT_LT(took_ns, 1'000'000'000) << read_file(dir.file("log.txt"));
  EXPECT_TRUE(WIFEXITED(c.status) && WEXITSTATUS(c.status) == 0) << read_file(dir.file("log.txt"));
  sm.receive(0);
  EXPECT_EQ(sm.count("STOPPING=1"), 1);
}

TEST(ServiceProcess, CheckConfigAcceptsTheShippedExample) {
  const RunResult r = run_mocap("run --check-config " + source_dir() + "/deploy/mocap.yaml");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("mocap.yaml: OK (sim cameras"), std::string::npos) << r.output;
}

TEST(ServiceProcess, CheckConfigRejectsWithOneLine) {
  TempDir dir("svc_check");
  write_file(dir.file("bad.yaml"), "pipeline:\n  trigger_rate: 100\n");
  const RunResult r = run_mocap("run --check-config " + dir.file("bad.yaml"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(r.output, "mocap: " + dir.file("bad.yaml") +
                          ": pipeline.trigger_rate: unknown key (line 2); expected one of: "
                          "trigger_rate_hz, pacing, realtime, lock_memory, cpu_latency_us, "
                          "dequeue_timeout_ms, stages, pair_by, pair_tolerance_us, every_frame, "
                          "catch_up_ms\n");
}

TEST(ServiceProcess, RunWithABadConfigFailsBeforeStarting) {
  TempDir dir("svc_badrun");
  write_file(dir.file("bad.yaml"), "outputs: {udp: ['nohost']}\n");
  const RunResult r = run_mocap("run --config " + dir.file("bad.yaml") + " --duration 5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("outputs.udp[0]: expected HOST:PORT, got 'nohost'"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace mocap::test
