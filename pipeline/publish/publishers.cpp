// Design: see publishers.h.
#include "pipeline/publish/publishers.h"

#include <time.h>

namespace mocap::publish {

Expected<Publishers> Publishers::create(const PublishersConfig& config) {
  auto udp = UdpPublisher::create(config.udp_destinations, config.multicast);
  if (!udp) return udp.error();
  Publishers p(std::move(udp.value()));
  p.stamped_ = std::make_unique<client::JointsMessage>();
  p.stamp_publish_ns_ = config.stamp_publish_ns;
  if (config.iceoryx) {
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
    auto shm = IceoryxPublisher::create(config.iceoryx_app_name, config.roudi_socket_path);
    if (shm) {
      p.shm_ = std::move(shm.value());
    } else if (shm.error().message == kNoRouDiMessage) {
      p.notice_ = kNoRouDiMessage;
    } else {
      return shm.error();
    }
#else
    p.notice_ = "iceoryx: not built in; publishing over UDP only";
#endif
  }
  return p;
}

bool Publishers::iceoryx_active() const noexcept {
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  return shm_ != nullptr;
#else
  return false;
#endif
}

bool Publishers::publish(const client::JointsMessage& msg) noexcept {
  ++frames_;
  const client::JointsMessage* out = &msg;
  if (stamp_publish_ns_) {
    *stamped_ = msg;
    timespec ts{};
    ::clock_gettime(CLOCK_MONOTONIC, &ts);
    stamped_->publish_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
    out = stamped_.get();
  }
  bool ok = true;
  if (udp_.destination_count() > 0) ok = udp_.publish(*out) && ok;
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  if (shm_) ok = shm_->publish(*out) && ok;
#endif
  return ok;
}

}  // namespace mocap::publish
