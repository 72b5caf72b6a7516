// `mocap echo [--udp HOST:PORT] [--multicast-if ADDR] [--iceoryx] [--count N]
// [--duration S] [--format text|csv|json]`: prints the live joint angles that `mocap run`
// publishes, received through the client library exactly as a motor controller would
// (client/udp_receiver.h, client/iceoryx_subscriber.h). One line per received message on stdout:
// sequence number, age (now - trigger time, CLOCK_MONOTONIC: meaningful when tracker and echo share
// a machine), the sequence gap since the previous message (frames dropped on the way) and every
// joint's angles in degrees. --format csv prints a header and one row per joint and message (angles
// in degrees, as the spec's CSV files), --format json one JSON object per message and line
// (radians); both end with the joint's quality (solved_by and the standard deviations of the
// angles; see docs/client.md) and its rates with their standard deviations, where the transport
// carries them (iceoryx, UDP datagram v2; v1 does not: empty/null) and the rates are known. --count
// / --duration stop it; SIGINT/SIGTERM stop it cleanly (the handler only sets an atomic flag; RouDi
// also SIGTERMs its clients when it shuts down). A summary line goes to stderr at the end. Setup
// failures (port in use, RouDi absent, bad address) are one line and exit code 2.
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
#include "client/datagram.h"
#include "client/joints_message.h"
#include "client/udp_receiver.h"
#include "core/clock.h"
#include "core/units.h"
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
  std::string format = "text";
};

constexpr const char* kCsvHeader =
    "seq,capture_ns,age_ms,gap,flags,joint,type,valid,a0_deg,a1_deg,a2_deg,qw,qx,qy,qz,"
    "solved_by,sd0_deg,sd1_deg,sd2_deg,da0_deg_s,da1_deg_s,da2_deg_s,sd_da0_deg_s,sd_da1_deg_s,"
    "sd_da2_deg_s";

const char* solved_by_name(std::uint8_t s) {
  switch (static_cast<client::SolvedBy>(s)) {
    case client::SolvedBy::kNone:
      return "none";
    case client::SolvedBy::kPoses:
      return "poses";
    case client::SolvedBy::kChain:
      return "chain";
  }
  return "unknown";
}

// `quality`: false when the transport does not carry JointQuality (UDP datagram v1): the
// quality columns are then empty (csv) or null (json), never a made-up value.
void print_csv(const client::JointsMessage& m, std::uint64_t gap, double age_ms, bool quality) {
  for (std::size_t j = 0; j < m.joint_count && j < client::kMaxJoints; ++j) {
    const client::JointRecord& r = m.joints[j];
    const client::JointQuality& q = m.quality[j];
    const bool hinge = r.type == static_cast<std::uint8_t>(client::JointKind::kHinge);
    char tail[256] = ",,,,,,,,,";
    if (quality) {
      const int n =
          std::snprintf(tail, sizeof tail, "%s,%.6f,%.6f,%.6f", solved_by_name(q.solved_by),
                        static_cast<double>(q.sd_rad[0]) * kDegPerRad,
                        static_cast<double>(q.sd_rad[1]) * kDegPerRad,
                        static_cast<double>(q.sd_rad[2]) * kDegPerRad);
      const client::JointRates& rt = m.rates[j];
      const std::size_t used = n > 0 ? static_cast<std::size_t>(n) : 0;
      if (rt.valid && used < sizeof tail) {
        std::snprintf(tail + used, sizeof tail - used, ",%.4f,%.4f,%.4f,%.4f,%.4f,%.4f",
                      static_cast<double>(rt.rate_rad_s[0]) * kDegPerRad,
                      static_cast<double>(rt.rate_rad_s[1]) * kDegPerRad,
                      static_cast<double>(rt.rate_rad_s[2]) * kDegPerRad,
                      static_cast<double>(rt.sd_rad_s[0]) * kDegPerRad,
                      static_cast<double>(rt.sd_rad_s[1]) * kDegPerRad,
                      static_cast<double>(rt.sd_rad_s[2]) * kDegPerRad);
      } else if (used < sizeof tail) {
        std::snprintf(tail + used, sizeof tail - used, ",,,,,,");
      }
    }
    std::printf("%llu,%lld,%.3f,%llu,%u,%u,%s,%u,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,%s\n",
                static_cast<unsigned long long>(m.sequence), static_cast<long long>(m.capture_ns),
                age_ms, static_cast<unsigned long long>(gap), static_cast<unsigned>(m.flags),
                static_cast<unsigned>(r.index), hinge ? "hinge" : "ball",
                static_cast<unsigned>(r.valid), static_cast<double>(r.a[0]) * kDegPerRad,
                static_cast<double>(r.a[1]) * kDegPerRad, static_cast<double>(r.a[2]) * kDegPerRad,
                static_cast<double>(r.q[0]), static_cast<double>(r.q[1]),
                static_cast<double>(r.q[2]), static_cast<double>(r.q[3]), tail);
  }
}

// A JSON number (9 significant digits, or 3 decimals when `millis`), or null for
// NaN/infinity (JSON has neither).
std::string json_number(double v, bool millis = false) {
  if (!std::isfinite(v)) return "null";
  char buf[48];
  if (millis) {
    std::snprintf(buf, sizeof buf, "%.3f", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.9g", v);
  }
  return buf;
}

std::string json_array(const float* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? "," : "") + json_number(static_cast<double>(v[i]));
  return s + "]";
}

void print_json(const client::JointsMessage& m, std::uint64_t gap, double age_ms, bool quality) {
  std::string s =
      "{\"seq\":" + std::to_string(m.sequence) + ",\"capture_ns\":" + std::to_string(m.capture_ns) +
      ",\"publish_ns\":" + std::to_string(m.publish_ns) +
      ",\"age_ms\":" + json_number(age_ms, true) + ",\"gap\":" + std::to_string(gap) +
      ",\"flags\":" + std::to_string(m.flags) +
      ",\"all_bodies_found\":" + ((m.flags & client::kFlagAllBodiesFound) ? "true" : "false") +
      ",\"joints\":[";
  for (std::size_t j = 0; j < m.joint_count && j < client::kMaxJoints; ++j) {
    const client::JointRecord& r = m.joints[j];
    const client::JointQuality& q = m.quality[j];
    const bool hinge = r.type == static_cast<std::uint8_t>(client::JointKind::kHinge);
    s += std::string(j ? "," : "") + "{\"index\":" + std::to_string(r.index) + ",\"type\":\"" +
         (hinge ? "hinge" : "ball") + "\",\"valid\":" + (r.valid ? "true" : "false") +
         ",\"a_rad\":" + json_array(r.a, 3) + ",\"q\":" + json_array(r.q, 4) + ",\"solved_by\":" +
         (quality ? "\"" + std::string(solved_by_name(q.solved_by)) + "\"" : std::string("null")) +
         ",\"sd_rad\":" + (quality ? json_array(q.sd_rad, 3) : std::string("null"));
    const bool rates = quality && m.rates[j].valid;
    s +=
        ",\"rate_rad_s\":" + (rates ? json_array(m.rates[j].rate_rad_s, 3) : std::string("null")) +
        ",\"rate_sd_rad_s\":" + (rates ? json_array(m.rates[j].sd_rad_s, 3) : std::string("null")) +
        "}";
  }
  s += "],\"predicted_lead_us\":" +
       ((m.flags & client::kFlagPredicted) ? std::to_string(m.lead_us) : std::string("null")) +
       "}\n";
  std::fputs(s.c_str(), stdout);
}

void print_message(const client::JointsMessage& m, std::uint64_t gap, const std::string& format,
                   bool quality) {
  const double age_ms = static_cast<double>(monotonic_ns() - m.capture_ns) * 1e-6;
  if (format != "text") {
    if (format == "csv") {
      print_csv(m, gap, age_ms, quality);
    } else {
      print_json(m, gap, age_ms, quality);
    }
    std::fflush(stdout);
    return;
  }
  std::printf("seq %llu age %.3f ms gap %llu%s", static_cast<unsigned long long>(m.sequence),
              age_ms, static_cast<unsigned long long>(gap),
              (m.flags & client::kFlagAllBodiesFound) ? "" : " (bodies missing)");
  if (m.flags & client::kFlagPredicted)
    std::printf(" predicted to publish + %.3f ms", static_cast<double>(m.lead_us) * 1e-3);
  for (std::size_t j = 0; j < m.joint_count && j < client::kMaxJoints; ++j) {
    const client::JointRecord& r = m.joints[j];
    const bool hinge = r.type == static_cast<std::uint8_t>(client::JointKind::kHinge);
    if (r.valid == 0) {
      std::printf(" | j%u %s --", static_cast<unsigned>(r.index), hinge ? "hinge" : "ball");
    } else if (hinge) {
      std::printf(" | j%u hinge %.2f", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0]) * kDegPerRad);
    } else {
      std::printf(" | j%u ball %.2f %.2f %.2f", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0]) * kDegPerRad,
                  static_cast<double>(r.a[1]) * kDegPerRad,
                  static_cast<double>(r.a[2]) * kDegPerRad);
    }
    const client::JointRates& rt = m.rates[j];
    if (quality && r.valid != 0 && rt.valid != 0) {  // the rates, deg/s
      if (hinge) {
        std::printf(" (%+.1f/s)", static_cast<double>(rt.rate_rad_s[0]) * kDegPerRad);
      } else {
        std::printf(" (%+.1f %+.1f %+.1f /s)", static_cast<double>(rt.rate_rad_s[0]) * kDegPerRad,
                    static_cast<double>(rt.rate_rad_s[1]) * kDegPerRad,
                    static_cast<double>(rt.rate_rad_s[2]) * kDegPerRad);
      }
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
    print_message(rx->latest(), gap, a.format, rx->latest_version() >= client::kDatagramVersion2);
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
    print_message(m, gap, a.format, true);
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
  if (a.format == "csv") {
    std::printf("%s\n", kCsvHeader);
    std::fflush(stdout);
  }
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
  cmd->add_option("--format", args->format,
                  "Output: text (default), csv (one row per joint, degrees) or json (one "
                  "object per message and line, radians)")
      ->check(CLI::IsMember({"text", "csv", "json"}));
  cmd->callback([args, &exit_code] { exit_code = run_echo(*args); });
}

const CommandRegistrar kEchoRegistrar(65, register_echo);

}  // namespace
}  // namespace mocap::app
