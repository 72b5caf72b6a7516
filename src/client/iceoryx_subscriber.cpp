// Design: see iceoryx_subscriber.h. take() hands out a Sample (a shared-memory chunk,
// released at scope end); the payload is copied out so consumers never hold chunks.
#include "client/iceoryx_subscriber.h"

#include <iceoryx_posh/popo/subscriber.hpp>

#include "client/iceoryx_runtime.h"

namespace mocap::client {

struct IceoryxSubscriber::Impl {
  explicit Impl(const iox::popo::SubscriberOptions& options)
      : sub(
            iox::capro::ServiceDescription{
                iox::capro::IdString_t(kIceoryxService),
                iox::capro::IdString_t(kIceoryxInstance),
                iox::capro::IdString_t(kIceoryxEvent)},
            options) {}
  iox::popo::Subscriber<JointsMessage> sub;
};

IceoryxSubscriber::IceoryxSubscriber(std::unique_ptr<Impl> impl) noexcept
    : impl_(std::move(impl)) {}
IceoryxSubscriber::~IceoryxSubscriber() = default;

Expected<std::unique_ptr<IceoryxSubscriber>> IceoryxSubscriber::create(
    const std::string& app_name, std::uint64_t queue_capacity) {
  auto rt = init_iceoryx_runtime(app_name);
  if (!rt) return rt.error();
  if (queue_capacity == 0) {
    return make_error("iceoryx subscriber", "queue_capacity", "must be at least 1");
  }
  iox::popo::SubscriberOptions options;
  options.queueCapacity = queue_capacity;
  options.historyRequest = 1;
  return std::unique_ptr<IceoryxSubscriber>(new IceoryxSubscriber(std::make_unique<Impl>(options)));
}

bool IceoryxSubscriber::subscribed() const noexcept {
  return impl_->sub.getSubscriptionState() == iox::SubscribeState::SUBSCRIBED;
}

bool IceoryxSubscriber::take_latest(JointsMessage& out) noexcept {
  bool got = false;
  for (int i = 0; i < 1024; ++i) {  // bounded drain
    auto result = impl_->sub.take();
    if (result.has_error()) break;
    const JointsMessage& msg = *result.value();
    ++counters_.received;
    if (have_last_ && msg.sequence <= last_sequence_) {
      ++counters_.stale;
      continue;
    }
    if (have_last_) counters_.dropped_frames += msg.sequence - last_sequence_ - 1;
    have_last_ = true;
    last_sequence_ = msg.sequence;
    out = msg;
    got = true;
  }
  return got;
}

}  // namespace mocap::client
