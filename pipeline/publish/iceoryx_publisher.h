// Design: tracker side of the shared-memory transport: an iceoryx Publisher of
// client::JointsMessage on service "mocap", instance "tracker", event "joints", with a
// history of 1 so late subscribers get the newest message. create() fails fast (never
// blocks) when RouDi is not running. publish() loans a shared-memory chunk, copies the
// message and publishes it: noexcept, no heap allocation; a failed loan is counted.
// Only declared when mocap_client was built with iceoryx (MOCAP_CLIENT_HAVE_ICEORYX).
#pragma once

#ifdef MOCAP_CLIENT_HAVE_ICEORYX

#include <cstdint>
#include <memory>
#include <string>

#include "client/joints_message.h"
#include "core/expected.h"

namespace mocap::publish {

inline constexpr const char* kNoRouDiMessage =
    "iceoryx: RouDi (iox-roudi) not running; publishing over UDP only";

struct IceoryxPublisherCounters {
  std::uint64_t published = 0;
  std::uint64_t loan_failures = 0;  // no free chunk in the mempool (slow subscribers)
};

class IceoryxPublisher {
 public:
  // `app_name`: this process's iceoryx runtime name. Error kNoRouDiMessage without RouDi.
  static Expected<std::unique_ptr<IceoryxPublisher>> create(
      const std::string& app_name = "mocap_tracker", const char* roudi_socket_path = "/tmp/roudi");
  ~IceoryxPublisher();
  IceoryxPublisher(const IceoryxPublisher&) = delete;
  IceoryxPublisher& operator=(const IceoryxPublisher&) = delete;

  bool publish(const client::JointsMessage& msg) noexcept;
  // True while at least one subscriber is connected.
  bool has_subscribers() const noexcept;
  const IceoryxPublisherCounters& counters() const noexcept { return counters_; }

 private:
  struct Impl;
  explicit IceoryxPublisher(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
  IceoryxPublisherCounters counters_{};
};

}  // namespace mocap::publish

#endif  // MOCAP_CLIENT_HAVE_ICEORYX
