// Design: the iceoryx shared-memory output as an OutputSink: IceoryxPublisher
// (iceoryx_publisher.h) loans a chunk, copies FrameResult::joints and publishes, on the
// publish thread (no heap allocation; a failed loan is a counted failure). Registered as
// "iceoryx": value true/false; options app_name and roudi_socket (tests). Without RouDi,
// or when mocap was built without iceoryx, there is no sink and one notice line.
#include <memory>
#include <string>

#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/output_registry.h"
#include "rt/counter.h"

namespace mocap::publish {
namespace {

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
class IceoryxSink final : public OutputSink {
 public:
  explicit IceoryxSink(std::unique_ptr<IceoryxPublisher> p) : p_(std::move(p)) {}
  const char* name() const noexcept override { return "iceoryx"; }
  bool publish(const FrameResult& frame) noexcept override {
    const bool ok = p_->publish(frame.joints);
    (ok ? published_ : failures_).add();
    return ok;
  }
  OutputCounters counters() const noexcept override {
    OutputCounters c;
    c.published = published_.get();
    c.failures = failures_.get();
    return c;
  }

 private:
  std::unique_ptr<IceoryxPublisher> p_;
  rt::Counter published_, failures_;
};
#endif

Expected<void> check_iceoryx(const OutputRequest& r) {
  auto on = request_flag(r);
  if (!on) return on.error();
  return {};
}

Expected<OutputCreated> create_iceoryx(const OutputRequest& r, const OutputContext&) {
  OutputCreated out;
  auto on = request_flag(r);
  if (!on) return on.error();
  if (!*on) return out;
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  const std::string* app = r.option("app_name");
  const std::string* socket = r.option("roudi_socket");
  auto shm = IceoryxPublisher::create(app ? *app : std::string("mocap_tracker"),
                                      socket ? socket->c_str() : "/tmp/roudi");
  if (shm) {
    out.sink = std::make_unique<IceoryxSink>(std::move(shm).value());
  } else if (shm.error().message == kNoRouDiMessage) {
    out.notice = kNoRouDiMessage;
  } else {
    return shm.error();
  }
#else
  out.notice = "iceoryx: not built in; publishing over UDP only";
#endif
  return out;
}

}  // namespace

extern const OutputKind kIceoryxOutput;
const OutputKind kIceoryxOutput{"iceoryx", "joint angles over iceoryx shared memory (iox-roudi)",
                                "app_name roudi_socket", &check_iceoryx, &create_iceoryx};

}  // namespace mocap::publish
