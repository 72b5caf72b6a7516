// Design: the iceoryx shared-memory output as an OutputSink: IceoryxPublisher
// (iceoryx_publisher.h) loans a chunk, copies FrameResult::joints and publishes, on the
// publish thread (no heap allocation; a failed loan is a counted failure). Registered as
// "iceoryx": value true/false; options app_name and roudi_socket (tests), lead_ms (the
// state predicted to publish + lead, lead.h). Without RouDi,
// or when mocap was built without iceoryx, there is no sink and one notice line.
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/lead.h"
#include "pipeline/publish/output_registry.h"
#include "rt/counter.h"

namespace mocap::publish {
namespace {

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
class IceoryxSink final : public OutputSink {
 public:
  IceoryxSink(std::unique_ptr<IceoryxPublisher> p, std::optional<LeadPredictor> lead)
      : p_(std::move(p)), lead_(lead) {}
  const char* name() const noexcept override { return "iceoryx"; }
  bool publish(const FrameResult& frame) noexcept override {
    const client::JointsMessage* msg = &frame.joints;
    if (lead_) {
      if (!lead_->apply(frame.joints, predicted_)) not_predicted_.add();
      msg = &predicted_;
    }
    const bool ok = p_->publish(*msg);
    (ok ? published_ : failures_).add();
    return ok;
  }
  OutputCounters counters() const noexcept override {
    OutputCounters c;
    c.published = published_.get();
    c.failures = failures_.get();
    c.not_predicted = not_predicted_.get();
    return c;
  }

 private:
  std::unique_ptr<IceoryxPublisher> p_;
  std::optional<LeadPredictor> lead_;
  client::JointsMessage predicted_{};  // publish thread only
  rt::Counter published_, failures_, not_predicted_;
};
#endif

// The lead_ms option: the state predicted to publish + lead (lead.h); none when absent.
Expected<std::optional<LeadPredictor>> iceoryx_lead(const OutputRequest& r,
                                                    const JointModel* model) {
  const std::string* l = r.option("lead_ms");
  if (l == nullptr) return std::optional<LeadPredictor>{};
  char* stop = nullptr;
  const double lead = std::strtod(l->c_str(), &stop);
  if (l->empty() || stop != l->c_str() + l->size())
    return make_error(r.where, "lead_ms '" + *l + "'", "expected milliseconds");
  if (lead == 0.0) return std::optional<LeadPredictor>{};
  auto p = LeadPredictor::create(lead, model, r.where);
  if (!p) return p.error();
  return std::optional<LeadPredictor>{*p};
}

Expected<void> check_iceoryx(const OutputRequest& r) {
  auto on = request_flag(r);
  if (!on) return on.error();
  auto lead = iceoryx_lead(r, nullptr);
  if (!lead) return lead.error();
  return {};
}

Expected<OutputCreated> create_iceoryx(const OutputRequest& r, const OutputContext& context) {
  OutputCreated out;
  auto on = request_flag(r);
  if (!on) return on.error();
  if (!*on) return out;
  auto lead = iceoryx_lead(r, context.model);
  if (!lead) return lead.error();
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  const std::string* app = r.option("app_name");
  const std::string* socket = r.option("roudi_socket");
  auto shm = IceoryxPublisher::create(app ? *app : std::string("mocap_tracker"),
                                      socket ? socket->c_str() : "/tmp/roudi");
  if (shm) {
    out.sink = std::make_unique<IceoryxSink>(std::move(shm).value(), *lead);
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
                                "app_name roudi_socket lead_ms", &check_iceoryx, &create_iceoryx};

}  // namespace mocap::publish
