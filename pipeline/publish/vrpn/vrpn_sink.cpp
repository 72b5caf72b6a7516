// Design: the VRPN server as an output of the seam (pipeline/publish; docs/vrpn.md): a
// QueuedSink, so the real-time publish thread only copies the frame result into a
// bounded drop-oldest queue (kVrpnFrameQueueDepth frames); this sink's worker thread is the
// server's one thread: per frame it services the sockets (vrpn::Server::poll: accepts,
// connection requests, client messages, flushes, deadlines) and sends the frame's
// reports to every client; with no frame it services them from idle() (about every
// 100 ms). Registered as output "vrpn" (`--vrpn [ADDR:]PORT`, `outputs: {vrpn:
// "[ADDR:]PORT"}`), options max_clients, client_buffer_kib and stall_ms.
// Message times: the capture time on the system clock (capture_clock.h, the offset taken
// at setup as for ROS 2). counters().dropped = frames dropped by the sink's queue +
// frames whose reports a client's full buffer or socket did not take.
#include <time.h>

#include <memory>
#include <string>

#include "pipeline/publish/capture_clock.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/queued_sink.h"
#include "pipeline/publish/vrpn/vrpn_server.h"

namespace mocap::publish {

namespace {

constexpr int kVrpnFrameQueueDepth = 4;  // frames waiting for the server thread

std::int64_t vrpn_monotonic_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

class VrpnSink final : public QueuedSink {
 public:
  VrpnSink(std::unique_ptr<vrpn::Server> server, std::string notice)
      : QueuedSink(kVrpnFrameQueueDepth),
        server_(std::move(server)),
        notice_(std::move(notice)),
        realtime_offset_ns_(realtime_offset_ns()) {}
  ~VrpnSink() override { stop(); }  // the worker uses the server: stop it first

  const char* name() const noexcept override { return "vrpn"; }
  std::string notice() const override { return notice_; }
  OutputCounters counters() const noexcept override {
    OutputCounters c = QueuedSink::counters();
    c.dropped += server_->counters().frames_dropped;
    return c;
  }

 protected:
  void encode(const FrameResult& frame) override {
    const std::int64_t now = vrpn_monotonic_ns();
    server_->poll(now);
    server_->send_frame(frame, realtime_offset_ns_, now);
  }
  void idle() override { server_->poll(vrpn_monotonic_ns()); }

 private:
  std::unique_ptr<vrpn::Server> server_;
  const std::string notice_;
  const std::int64_t realtime_offset_ns_;
};

// An integer option in [lo, hi] or the default.
Expected<vrpn::ServerOptions> vrpn_options_of(const OutputRequest& r) {
  if (r.values.size() != 1)
    return make_error(
        r.where, "",
        "expected one [ADDRESS:]PORT, got " + std::to_string(r.values.size()) + " values");
  vrpn::ServerOptions o;
  if (auto a = vrpn::parse_listen_address(r.values[0], r.where, o); !a) return a.error();
  auto clients = r.int_option("max_clients", o.max_clients, 1, 64);
  if (!clients) return clients.error();
  auto kib =
      r.int_option("client_buffer_kib", static_cast<int>(o.client_buffer_bytes / 1024), 16, 16384);
  if (!kib) return kib.error();
  auto stall = r.int_option("stall_ms", o.stall_ms, 100, 60000);
  if (!stall) return stall.error();
  o.max_clients = *clients;
  o.client_buffer_bytes = static_cast<std::size_t>(*kib) * 1024;
  o.stall_ms = *stall;
  return o;
}

Expected<void> check_vrpn(const OutputRequest& r) {
  auto o = vrpn_options_of(r);
  if (!o) return o.error();
  return {};
}

Expected<OutputCreated> create_vrpn(const OutputRequest& r, const OutputContext& ctx) {
  auto o = vrpn_options_of(r);
  if (!o) return o.error();
  if (ctx.targets == nullptr) return make_error(r.where, "", "needs the targets (none given)");
  if (ctx.frame_rate_hz > 0.0) o->frame_period_s = 1.0 / ctx.frame_rate_hz;
  std::vector<std::string> bodies;
  for (const MarkerTarget& b : ctx.targets->bodies) bodies.push_back(b.name);
  auto server = vrpn::Server::create(*o, bodies);
  if (!server) {  // "vrpn: ..." or "ADDR:PORT: cannot listen: ..." -> under the request's key
    std::string m = server.error().message;
    if (m.rfind("vrpn: ", 0) == 0) m.erase(0, 6);
    return make_error(r.where, "", m);
  }
  const std::string at = o->address + ":" + std::to_string((*server)->port());
  std::string notice = "vrpn: " + std::to_string(bodies.size()) + " trackers on " + at + " (";
  notice += bodies.empty() ? std::string("none") : bodies.front() + "@" + at;
  notice += bodies.size() > 1 ? ", ...)" : ")";
  auto sink = std::make_unique<VrpnSink>(std::move(*server), notice);
  if (auto s = sink->start(); !s) return s.error();
  OutputCreated out;
  out.notice = sink->notice();
  out.sink = std::move(sink);
  return out;
}

}  // namespace

extern const OutputKind kVrpnOutput;
const OutputKind kVrpnOutput{"vrpn",
                             "VRPN server (one tracker per body) on [ADDRESS:]PORT (docs/vrpn.md)",
                             "max_clients client_buffer_kib stall_ms", &check_vrpn, &create_vrpn};

}  // namespace mocap::publish
