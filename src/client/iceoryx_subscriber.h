// Design: consumer side of the shared-memory transport (service "mocap", instance
// "tracker", event "joints", payload JointsMessage). create() initialises the process's
// iceoryx runtime (never blocking: it checks RouDi first) and subscribes with a history
// request of 1, so a late subscriber gets the newest message. take_latest() drains the
// queue without blocking or allocating, keeps the newest message and counts sequence
// gaps as dropped frames. Pimpl keeps iceoryx headers out of consumers' includes.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "client/joints_message.h"
#include "core/expected.h"

namespace mocap::client {

struct SubscriberCounters {
  std::uint64_t received = 0;        // samples taken
  std::uint64_t dropped_frames = 0;  // sum of sequence gaps
  std::uint64_t stale = 0;           // sequence not newer than the last one
};

class IceoryxSubscriber {
 public:
  // `app_name`: this process's iceoryx runtime name (unique on the machine).
  // `queue_capacity`: samples buffered between two take_latest() calls (oldest dropped).
  static Expected<std::unique_ptr<IceoryxSubscriber>> create(const std::string& app_name,
                                                             std::uint64_t queue_capacity = 16);
  ~IceoryxSubscriber();
  IceoryxSubscriber(const IceoryxSubscriber&) = delete;
  IceoryxSubscriber& operator=(const IceoryxSubscriber&) = delete;

  // True when at least one new message was taken; `out` then holds the newest.
  bool take_latest(JointsMessage& out) noexcept;
  // True once a publisher is connected to this subscriber.
  bool subscribed() const noexcept;
  const SubscriberCounters& counters() const noexcept { return counters_; }

 private:
  struct Impl;
  explicit IceoryxSubscriber(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
  SubscriberCounters counters_{};
  bool have_last_ = false;
  std::uint64_t last_sequence_ = 0;
};

}  // namespace mocap::client
