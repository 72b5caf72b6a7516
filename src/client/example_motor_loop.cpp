// Design: an example motor-controller loop consuming `mocap run` output. Every ~1 ms it
// takes the newest joint angles (UDP, plus iceoryx when built with it and RouDi runs),
// predicts them to the tick's own CLOCK_MONOTONIC instant (client/predict.h: needs the
// rates of iceoryx or UDP datagram version 2), and twice a second prints the angles
// (degrees), the prediction and the counters. A real controller would run its control law
// where the prediction is used. Everything after setup is allocation-free
// except the periodic printing.
//   mocap_client_example [BIND_HOST:PORT=127.0.0.1:9870] [SECONDS=10] [--iceoryx]
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "client/predict.h"
#include "client/udp_receiver.h"
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
#include "client/iceoryx_subscriber.h"
#endif

namespace {

constexpr float kDegPerRad = 57.29577951308232f;

void print_message(const char* source, const mocap::client::JointsMessage& m) {
  std::printf("[%s] seq %llu, %u joints%s\n", source, static_cast<unsigned long long>(m.sequence),
              static_cast<unsigned>(m.joint_count),
              (m.flags & mocap::client::kFlagAllBodiesFound) ? "" : " (some bodies missing)");
  for (std::size_t j = 0; j < m.joint_count; ++j) {
    const auto& r = m.joints[j];
    if (!r.valid) {
      std::printf("  joint %u: not tracked\n", static_cast<unsigned>(r.index));
    } else if (r.type == static_cast<std::uint8_t>(mocap::client::JointKind::kHinge)) {
      std::printf("  joint %u hinge: %8.3f deg\n", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0] * kDegPerRad));
    } else {
      std::printf("  joint %u ball:  %8.3f %8.3f %8.3f deg\n", static_cast<unsigned>(r.index),
                  static_cast<double>(r.a[0] * kDegPerRad),
                  static_cast<double>(r.a[1] * kDegPerRad),
                  static_cast<double>(r.a[2] * kDegPerRad));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string bind = "127.0.0.1:9870";
  double seconds = 10.0;
  bool use_iceoryx = false;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--iceoryx") == 0) {
      use_iceoryx = true;
    } else if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf("usage: %s [BIND_HOST:PORT=127.0.0.1:9870] [SECONDS=10] [--iceoryx]\n", argv[0]);
      return 0;
    } else if (positional == 0) {
      bind = argv[i];
      ++positional;
    } else if (positional == 1) {
      char* end = nullptr;
      seconds = std::strtod(argv[i], &end);
      if (end == argv[i] || *end != '\0' || !(seconds > 0.0)) {
        std::fprintf(stderr, "mocap_client_example: SECONDS: '%s' is not a positive number\n",
                     argv[i]);
        return 2;
      }
      ++positional;
    } else {
      std::fprintf(stderr, "mocap_client_example: unexpected argument '%s'\n", argv[i]);
      return 2;
    }
  }

  auto receiver = mocap::client::UdpReceiver::create(bind);
  if (!receiver) {
    std::fprintf(stderr, "%s\n", receiver.error().message.c_str());
    return 1;
  }
  std::printf("listening for datagram v1 on %s (port %u) for %.1f s\n", bind.c_str(),
              static_cast<unsigned>(receiver->port()), seconds);

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  std::unique_ptr<mocap::client::IceoryxSubscriber> shm;
  if (use_iceoryx) {
    auto sub = mocap::client::IceoryxSubscriber::create("mocap_client_example");
    if (sub) {
      shm = std::move(sub.value());
    } else {
      std::printf("%s; receiving over UDP only\n", sub.error().message.c_str());
    }
  }
#else
  if (use_iceoryx) std::printf("built without iceoryx; receiving over UDP only\n");
#endif

  mocap::client::JointsMessage shm_msg;
  bool have_shm = false;
  mocap::client::JointPrediction prediction;
  unsigned long long predicted = 0, refused = 0;  // ticks predicted / beyond the horizon
  const auto start = std::chrono::steady_clock::now();
  auto next_print = start + std::chrono::milliseconds(500);
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(seconds));
  while (std::chrono::steady_clock::now() < end) {
    receiver->wait(std::chrono::microseconds(1000));  // ~1 kHz control tick
    bool shm_new = false;
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
    if (shm) shm_new = shm->take_latest(shm_msg);
#endif
    have_shm = have_shm || shm_new;
    // The state at this tick's instant (steady_clock is CLOCK_MONOTONIC on Linux).
    const auto now = std::chrono::steady_clock::now();
    const std::int64_t now_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
    const mocap::client::JointsMessage* latest =
        have_shm ? &shm_msg : (receiver->has_message() ? &receiver->latest() : nullptr);
    if (latest) {
      if (mocap::client::predict(*latest, now_ns, prediction) ==
          mocap::client::PredictStatus::kOk) {
        ++predicted;  // control law goes here, using prediction.joints[j].a_rad / sd_rad
      } else {
        ++refused;  // the newest message is too old: hold or stop the motors
      }
    }
    if (now >= next_print) {
      next_print = now + std::chrono::milliseconds(500);
      if (receiver->has_message()) print_message("udp", receiver->latest());
      if (shm_new) print_message("shm", shm_msg);
      if (predicted > 0 && prediction.joint_count > 0 && prediction.joints[0].valid) {
        std::printf("predicted +%.1f ms: joint 0 a0 %.3f deg (sd %.3f)\n", prediction.dt_s * 1e3,
                    static_cast<double>(prediction.joints[0].a_rad[0] * kDegPerRad),
                    static_cast<double>(prediction.joints[0].sd_rad[0] * kDegPerRad));
      }
      std::printf("ticks predicted %llu, refused (beyond the horizon) %llu\n", predicted, refused);
      const auto& c = receiver->counters();
      std::printf(
          "udp: accepted %llu, dropped frames %llu, rejected %llu (crc %llu, length %llu), "
          "stale %llu\n",
          static_cast<unsigned long long>(c.accepted),
          static_cast<unsigned long long>(c.dropped_frames),
          static_cast<unsigned long long>(c.rejected_total()),
          static_cast<unsigned long long>(c.rejected_for(mocap::client::DecodeStatus::kBadCrc)),
          static_cast<unsigned long long>(c.rejected_for(mocap::client::DecodeStatus::kBadLength)),
          static_cast<unsigned long long>(c.stale));
    }
  }
  return 0;
}
