// Design: the UDP datagram v1 output (spec "UDP datagram") as an OutputSink: the
// UdpPublisher transport (udp_publisher.h) sends FrameResult::joints to every configured
// destination from the publish thread (sendto with MSG_DONTWAIT: never blocks). Counters
// for other threads are rt::Counters of this sink (the transport's own are publish-thread
// data). Registered as "udp": values = "HOST:PORT" destinations (none: no UDP output);
// options multicast_if / multicast_ttl (the --multicast-* flags) and versions ("1,2,..."
// one datagram version per destination, from the map form of outputs.udp; default 1).
#include <memory>
#include <string>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/udp_publisher.h"
#include "rt/counter.h"

namespace mocap::publish {
namespace {

class UdpSink final : public OutputSink {
 public:
  explicit UdpSink(UdpPublisher udp) : udp_(std::move(udp)) {}
  const char* name() const noexcept override { return "udp"; }
  bool publish(const FrameResult& frame) noexcept override {
    const UdpPublisher::Status s = udp_.publish(frame.joints);
    if (s == UdpPublisher::Status::kFailed) {
      failures_.add();
      return false;
    }
    published_.add();
    if (s == UdpPublisher::Status::kSentNoListener) no_listener_.add();
    return true;
  }
  OutputCounters counters() const noexcept override {
    OutputCounters c;
    c.published = published_.get();
    c.failures = failures_.get();
    c.no_listener = no_listener_.get();
    return c;
  }

 private:
  UdpPublisher udp_;
  rt::Counter published_, failures_, no_listener_;
};

// "1,2,1" -> {1, 2, 1}; empty on a malformed list.
std::vector<std::uint16_t> parse_versions(const std::string& text) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 0; i < text.size(); i += 2) {
    if ((text[i] != '1' && text[i] != '2') || (i + 1 < text.size() && text[i + 1] != ','))
      return {};
    out.push_back(static_cast<std::uint16_t>(text[i] - '0'));
  }
  return out;
}

Expected<void> check_udp(const OutputRequest& r) {
  if (const std::string* v = r.option("versions")) {
    if (parse_versions(*v).size() != r.values.size())
      return make_error(r.where, "versions '" + *v + "'", "expected 1 or 2 per destination");
  }
  for (const std::string& d : r.values) {
    const std::size_t colon = d.rfind(':');
    bool ok = colon != std::string::npos && colon > 0 && colon + 1 < d.size() &&
              d.size() - colon - 1 <= 5;
    int port = 0;
    for (std::size_t i = colon + 1; ok && i < d.size(); ++i) {
      ok = d[i] >= '0' && d[i] <= '9';
      port = port * 10 + (d[i] - '0');
    }
    if (!ok || port < 1 || port > 65535)
      return make_error(r.where, "'" + d + "'", "expected HOST:PORT with a port in 1..65535");
  }
  if (const std::string* ttl = r.option("multicast_ttl")) {
    if (ttl->empty() || ttl->size() > 3 ||
        ttl->find_first_not_of("0123456789") != std::string::npos || std::stoi(*ttl) > 255)
      return make_error(r.where, "multicast ttl", "must be in 0..255, got '" + *ttl + "'");
  }
  return {};
}

Expected<OutputCreated> create_udp(const OutputRequest& r, const OutputContext&) {
  OutputCreated out;
  if (r.values.empty()) return out;
  UdpMulticastOptions mc;
  if (const std::string* i = r.option("multicast_if")) mc.interface = *i;
  if (const std::string* t = r.option("multicast_ttl")) mc.ttl = std::stoi(*t);
  std::vector<std::uint16_t> versions;
  if (const std::string* v = r.option("versions")) versions = parse_versions(*v);
  auto udp = UdpPublisher::create(r.values, mc, versions);
  if (!udp) return udp.error();
  out.sink = std::make_unique<UdpSink>(std::move(udp).value());
  return out;
}

}  // namespace

extern const OutputKind kUdpOutput;
const OutputKind kUdpOutput{"udp",
                            "joint angles as UDP datagrams (version 1, or 2 with quality and "
                            "rates) to HOST:PORT destinations",
                            "multicast_if multicast_ttl versions", &check_udp, &create_udp};

}  // namespace mocap::publish
