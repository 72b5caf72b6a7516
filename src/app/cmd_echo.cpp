// `mocap echo [--udp HOST:PORT] [--multicast-if ADDR] [--iceoryx] [--count N]
// [--duration S]`: prints the live joint angles that `mocap run` publishes, received
// through the client library exactly as a motor controller would (client/udp_receiver.h,
// client/iceoryx_subscriber.h). One line per received message on stdout: sequence number,
// age (now - trigger time, CLOCK_MONOTONIC: meaningful when tracker and echo share a
// machine), the sequence gap since the previous message (frames dropped on the way) and
// every joint's angles in degrees. --count / --duration stop it; SIGINT/SIGTERM stop it
// cleanly (the handler only sets an atomic flag; RouDi also SIGTERMs its clients when it
// shuts down). A summary line goes to stderr at the end. Setup failures (port in use,
// RouDi absent, bad address) are one line and exit code 2.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "app/command_registry.h"
#include "client/joints_message.h"
#include "client/udp_receiver.h"
#include "core/latency_stats.h"
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
#include "client/iceoryx_subscriber.h"
#endif

namespace mocap::app {
namespace {

std::atomic<bool> g_echo_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "used from a signal handler");

extern "C" void on_echo_signal(int) {
  // relaxed: a lock-free atomic store is async-signal-safe; the loop polls it.
  g_echo_stop.store(true, std::memory_order_relaxed);
}

struct EchoArgs {
  std::string udp = "0.0.0.0:7755";
  std::string multicast_if;
  bool iceoryx = false;
  long long count = 0;      // 0: unlimited
  double duration_s = 0.0;  // 0: until SIGINT/SIGTERM
};

constexpr double kRadToDeg = 180.0 / M_PI;

void print_message(const client::JointsMessage& m, std::uint64_t gap) {
  const double age_ms = static_cast<double>(monotonic_ns() - m.capture_ns) * 1e-6;
  std::printf("seq %llu age %.3f ms gap %llu%s", static_cast<unsigned long long>(m.sequence),
              age_ms, static_cast<unsigned long long>(gap),
              (m.flags & client::kFlagAllBodiesFound) ? "" : " (bodies missing)");
  for (std::size_t j = 0; j < m.joint_count && j < client::kMaxJoints; ++j) {
    const client::JointRecord& r = m.joints[j];
    const bool hinge = r.type == static_cast<std::uint8_t>(client::JointKind::kHinge);
    if (r.valid == 0) {
      std::printf(" | j%u %s --", static_cast<unsigned>(r.index), hinge ? "hinge" : "ball");
    } else if (hinge) {
      std::printf(" | j%u hinge %.2f", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0]) * kRadToDeg);
    } else {
      std::printf(" | j%u ball %.2f %.2f %.2f", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0]) * kRadToDeg, static_cast<double>(r.a[1]) * kRadToDeg,
                  static_cast<double>(r.a[2]) * kRadToDeg);
    }
  }
  std::printf(" deg\n");
  std::fflush(stdout);
}

// Stop conditions shared by both transports.
struct Limits {
  const EchoArgs& a;
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  bool done(long long printed) const {
    if (g_echo_stop.load(std::memory_order_relaxed)) return true;
    if (a.count > 0 && printed >= a.count) return true;
    return a.duration_s > 0.0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >=
               a.duration_s;
  }
};

int echo_udp(const EchoArgs& a) {
  auto rx = client::UdpReceiver::create(a.udp, a.multicast_if);
  if (!rx) return fail(rx.error().message);
  std::fprintf(stderr, "mocap echo: listening on %s%s (port %u)\n", a.udp.c_str(),
               rx->multicast() ? " (multicast group)" : "", static_cast<unsigned>(rx->port()));
  const Limits limits{a};
  long long printed = 0;
  std::uint64_t last_accepted = 0, last_dropped = 0;
  while (!limits.done(printed)) {
    rx->wait(std::chrono::milliseconds(50));
    const client::ReceiverCounters& c = rx->counters();
    if (c.accepted == last_accepted) continue;
    // wait() returns as soon as a datagram is there, so each line is normally one
    // message; the gap is the frames the tracker or the network dropped since the last.
    const std::uint64_t gap = c.dropped_frames - last_dropped;
    last_accepted = c.accepted;
    last_dropped = c.dropped_frames;
    print_message(rx->latest(), gap);
    ++printed;
  }
  const client::ReceiverCounters& c = rx->counters();
  std::fprintf(stderr,
               "mocap echo: %llu messages, %llu frames dropped (sequence gaps), %llu rejected, "
               "%llu stale, %llu tracker restarts\n",
               static_cast<unsigned long long>(c.accepted),
               static_cast<unsigned long long>(c.dropped_frames),
               static_cast<unsigned long long>(c.rejected_total()),
               static_cast<unsigned long long>(c.stale),
               static_cast<unsigned long long>(c.restarts));
  return 0;
}

int echo_iceoryx(const EchoArgs& a) {
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  auto sub = client::IceoryxSubscriber::create("mocap_echo_" + std::to_string(::getpid()));
  if (!sub) return fail(sub.error().message);
  std::fprintf(stderr, "mocap echo: subscribed to iceoryx mocap/tracker/joints\n");
  const Limits limits{a};
  long long printed = 0;
  std::uint64_t last_dropped = 0;
  client::JointsMessage m;
  while (!limits.done(printed)) {
    if (!(*sub)->take_latest(m)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    const client::SubscriberCounters& c = (*sub)->counters();
    const std::uint64_t gap = c.dropped_frames - last_dropped;
    last_dropped = c.dropped_frames;
    print_message(m, gap);
    ++printed;
  }
  const client::SubscriberCounters& c = (*sub)->counters();
  std::fprintf(
      stderr, "mocap echo: %llu messages, %llu frames dropped (sequence gaps), %llu stale\n",
      static_cast<unsigned long long>(c.received),
      static_cast<unsigned long long>(c.dropped_frames), static_cast<unsigned long long>(c.stale));
  return 0;
#else
  (void)a;
  return fail("--iceoryx: this build has no iceoryx support");
#endif
}

int run_echo(const EchoArgs& a) {
  if (a.count < 0) return fail("--count: must be >= 0");
  if (a.duration_s < 0.0) return fail("--duration: must be >= 0");
  struct sigaction sa {};
  sa.sa_handler = on_echo_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  return a.iceoryx ? echo_iceoryx(a) : echo_udp(a);
}

void register_echo(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<EchoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "echo", "Print the live joint angles of `mocap run` (UDP by default, or --iceoryx)");
  cmd->add_option("--udp", args->udp,
                  "Listen on HOST:PORT, or join the multicast group HOST (default 0.0.0.0:7755)");
  cmd->add_option("--multicast-if", args->multicast_if,
                  "Local interface address to join the multicast group on (e.g. 127.0.0.1)");
  cmd->add_flag("--iceoryx", args->iceoryx,
                "Read from iceoryx shared memory (needs iox-roudi) instead of UDP");
  cmd->add_option("--count", args->count, "Stop after printing N messages (default: no limit)");
  cmd->add_option("--duration", args->duration_s, "Stop after S seconds (default: until Ctrl-C)");
  cmd->callback([args, &exit_code] { exit_code = run_echo(*args); });
}

const CommandRegistrar kRegistrar(65, register_echo);

}  // namespace
}  // namespace mocap::app
