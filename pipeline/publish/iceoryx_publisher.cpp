// Design: see iceoryx_publisher.h. loan() returns a Sample owning a chunk of RouDi's
// mempool; assigning the payload and publish() hand the chunk to subscribers.
#include "pipeline/publish/iceoryx_publisher.h"

#ifdef MOCAP_CLIENT_HAVE_ICEORYX

#include <iceoryx_posh/popo/publisher.hpp>

#include "client/iceoryx_runtime.h"

namespace mocap::publish {

struct IceoryxPublisher::Impl {
  explicit Impl(const iox::popo::PublisherOptions& options)
      : pub(
            iox::capro::ServiceDescription{
                iox::capro::IdString_t(client::kIceoryxService),
                iox::capro::IdString_t(client::kIceoryxInstance),
                iox::capro::IdString_t(client::kIceoryxEvent)},
            options) {}
  iox::popo::Publisher<client::JointsMessage> pub;
};

IceoryxPublisher::IceoryxPublisher(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
IceoryxPublisher::~IceoryxPublisher() = default;

Expected<std::unique_ptr<IceoryxPublisher>> IceoryxPublisher::create(
    const std::string& app_name, const char* roudi_socket_path) {
  auto rt = client::init_iceoryx_runtime(app_name, roudi_socket_path);
  if (!rt) {
    if (rt.error().message == "iceoryx: RouDi (iox-roudi) not running")
      return Error{kNoRouDiMessage};
    return rt.error();
  }
  iox::popo::PublisherOptions options;
  options.historyCapacity = 1;
  return std::unique_ptr<IceoryxPublisher>(new IceoryxPublisher(std::make_unique<Impl>(options)));
}

bool IceoryxPublisher::publish(const client::JointsMessage& msg) noexcept {
  auto loaned = impl_->pub.loan();
  if (loaned.has_error()) {
    ++counters_.loan_failures;
    return false;
  }
  auto& sample = loaned.value();
  *sample = msg;
  sample.publish();
  ++counters_.published;
  return true;
}

bool IceoryxPublisher::has_subscribers() const noexcept { return impl_->pub.hasSubscribers(); }

}  // namespace mocap::publish

#endif  // MOCAP_CLIENT_HAVE_ICEORYX
