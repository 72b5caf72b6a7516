// Design: the UDP datagram v1 output (spec "UDP datagram") as an OutputSink: the
// UdpPublisher transport (udp_publisher.h) sends FrameResult::joints to every configured
// destination from the publish thread (sendto with MSG_DONTWAIT: never blocks). Counters
// for other threads are rt::Counters of this sink (the transport's own are publish-thread
// data). Registered as "udp": values = "HOST:PORT" destinations (none: no UDP output);
// options multicast_if / multicast_ttl (the --multicast-* flags) and versions ("1,2,..."
// one datagram version per destination, from the map form of outputs.udp; default 1) and
// leads_ms ("0,5,..." one lead per destination, the map form's lead_ms: those destinations
// get the state predicted to publish + lead, lead.h; one transport per distinct lead).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/publish/lead.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/udp_publisher.h"
#include "rt/counter.h"

namespace mocap::publish {
namespace {

class UdpSink final : public OutputSink {
 public:
  // One transport per distinct lead of the destinations (lead 0: the measured state).
  struct Group {
    UdpPublisher udp;
    std::optional<LeadPredictor> lead;
  };
  explicit UdpSink(std::vector<Group> groups) : groups_(std::move(groups)) {}
  const char* name() const noexcept override { return "udp"; }
  bool publish(const FrameResult& frame) noexcept override {
    bool failed = false, no_listener = false;
    for (Group& g : groups_) {
      const client::JointsMessage* msg = &frame.joints;
      if (g.lead) {
        if (!g.lead->apply(frame.joints, predicted_)) not_predicted_.add();
        msg = &predicted_;
      }
      const UdpPublisher::Status s = g.udp.publish(*msg);
      failed = failed || s == UdpPublisher::Status::kFailed;
      no_listener = no_listener || s == UdpPublisher::Status::kSentNoListener;
    }
    if (failed) {
      failures_.add();
      return false;
    }
    published_.add();
    if (no_listener) no_listener_.add();
    return true;
  }
  OutputCounters counters() const noexcept override {
    OutputCounters c;
    c.published = published_.get();
    c.failures = failures_.get();
    c.no_listener = no_listener_.get();
    c.not_predicted = not_predicted_.get();
    return c;
  }

 private:
  std::vector<Group> groups_;
  client::JointsMessage predicted_{};  // publish thread only
  rt::Counter published_, failures_, no_listener_, not_predicted_;
};

// "0,5.000,0" -> {0, 5, 0} (ms); empty on a malformed list.
std::vector<double> parse_leads(const std::string& text) {
  std::vector<double> out;
  std::size_t i = 0;
  while (i <= text.size()) {
    const std::size_t end = std::min(text.find(',', i), text.size());
    const std::string item = text.substr(i, end - i);
    char* stop = nullptr;
    const double v = std::strtod(item.c_str(), &stop);
    if (item.empty() || stop != item.c_str() + item.size() || !std::isfinite(v)) return {};
    out.push_back(v);
    i = end + 1;
  }
  return out;
}

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
  if (const std::string* l = r.option("leads_ms")) {
    const std::vector<double> leads = parse_leads(*l);
    if (leads.size() != r.values.size())
      return make_error(r.where, "leads_ms '" + *l + "'", "expected one lead per destination");
    for (const double lead : leads) {
      if (!(lead >= 0.0 && lead <= kMaxLeadMs))
        return make_error(r.where, "lead_ms", "must be in 0..50 milliseconds");
    }
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

Expected<OutputCreated> create_udp(const OutputRequest& r, const OutputContext& context) {
  OutputCreated out;
  if (r.values.empty()) return out;
  UdpMulticastOptions mc;
  if (const std::string* i = r.option("multicast_if")) mc.interface = *i;
  if (const std::string* t = r.option("multicast_ttl")) mc.ttl = std::stoi(*t);
  std::vector<std::uint16_t> versions(r.values.size(), 1);
  if (const std::string* v = r.option("versions")) versions = parse_versions(*v);
  std::vector<double> leads(r.values.size(), 0.0);
  if (const std::string* l = r.option("leads_ms")) leads = parse_leads(*l);
  // The destinations grouped by lead, in order of first appearance.
  std::vector<double> distinct;
  for (const double l : leads) {
    if (std::find(distinct.begin(), distinct.end(), l) == distinct.end()) distinct.push_back(l);
  }
  std::vector<UdpSink::Group> groups;
  for (const double lead : distinct) {
    std::vector<std::string> dest;
    std::vector<std::uint16_t> ver;
    for (std::size_t i = 0; i < r.values.size(); ++i) {
      if (leads[i] != lead) continue;
      dest.push_back(r.values[i]);
      ver.push_back(versions[i]);
    }
    auto udp = UdpPublisher::create(dest, mc, ver);
    if (!udp) return udp.error();
    UdpSink::Group g{std::move(udp).value(), std::nullopt};
    if (lead > 0.0) {
      auto p = LeadPredictor::create(lead, context.model, r.where);
      if (!p) return p.error();
      g.lead.emplace(*p);
    }
    groups.push_back(std::move(g));
  }
  out.sink = std::make_unique<UdpSink>(std::move(groups));
  return out;
}

}  // namespace

extern const OutputKind kUdpOutput;
const OutputKind kUdpOutput{"udp",
                            "joint angles as UDP datagrams (version 1, or 2 with quality and "
                            "rates) to HOST:PORT destinations",
                            "multicast_if multicast_ttl versions leads_ms", &check_udp,
                            &create_udp};

}  // namespace mocap::publish
