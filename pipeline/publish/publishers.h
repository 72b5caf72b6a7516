// Design: the one object the pipeline calls once per frame. Setup builds a UDP publisher
// for the configured destinations and, when asked, an iceoryx publisher; without RouDi
// the iceoryx part is skipped and `notice()` holds the one line to print once ("iceoryx:
// RouDi (iox-roudi) not running; publishing over UDP only"). publish() stamps the publish
// time (CLOCK_MONOTONIC, unless the caller stamps it) into a preallocated copy and sends
// it on every transport:
// noexcept, allocation-free, failures are the transports' counters.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "client/joints_message.h"
#include "core/expected.h"
#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/udp_publisher.h"

namespace mocap::publish {

struct PublishersConfig {
  std::vector<std::string> udp_destinations;  // "HOST:PORT"; may be empty
  UdpMulticastOptions multicast;              // used when a destination is a group
  bool iceoryx = true;                        // try shared memory (needs iox-roudi)
  std::string iceoryx_app_name = "mocap_tracker";
  const char* roudi_socket_path = "/tmp/roudi";  // tests only
  // True: publish() sets publish_ns = now (CLOCK_MONOTONIC) on a preallocated copy.
  // False: the caller already stamped publish_ns; the message is sent unchanged.
  bool stamp_publish_ns = true;
};

class Publishers {
 public:
  static Expected<Publishers> create(const PublishersConfig& config);

  // Publishes `msg` on every transport (publish_ns = now unless the config says the
  // caller stamps it). True if all succeeded.
  bool publish(const client::JointsMessage& msg) noexcept;

  bool iceoryx_active() const noexcept;
  const std::string& notice() const noexcept { return notice_; }  // empty or one line
  const UdpPublisher& udp() const noexcept { return udp_; }
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  const IceoryxPublisher* iceoryx() const noexcept { return shm_.get(); }
#endif
  std::uint64_t frames() const noexcept { return frames_; }

 private:
  explicit Publishers(UdpPublisher udp) noexcept : udp_(std::move(udp)) {}

  UdpPublisher udp_;
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  std::unique_ptr<IceoryxPublisher> shm_;
#endif
  std::string notice_;
  std::unique_ptr<client::JointsMessage> stamped_;  // preallocated copy (1 KiB)
  std::uint64_t frames_ = 0;
  bool stamp_publish_ns_ = true;
};

}  // namespace mocap::publish
