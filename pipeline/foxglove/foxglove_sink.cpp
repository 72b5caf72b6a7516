// Design: the Foxglove live view as an output of the seam (pipeline/publish): a
// QueuedSink, so the real-time publish thread only copies the frame result into a
// bounded drop-oldest queue; this sink's worker thread encodes the JSON messages of the
// channels some viewer subscribes to (encode.h; none when nobody watches) and hands
// them to the server (server.h), whose own io thread writes them to each viewer's
// bounded queue. Registered as output "foxglove" (`--foxglove [ADDR:]PORT`,
// `outputs: foxglove: "[ADDR:]PORT"`); options max_clients and client_queue.
// Timestamps: capture time moved from CLOCK_MONOTONIC to the wall clock (offset taken
// at setup), since the Foxglove app shows and orders messages by wall-clock time.
// counters().dropped = frames dropped by the sink's queue + messages dropped by viewers'
// queues (both are "the viewer did not get this", see docs/foxglove.md).
#include <time.h>

#include <cstdint>
#include <memory>
#include <string>

#include "pipeline/foxglove/blob_overlay.h"
#include "pipeline/foxglove/encode.h"
#include "pipeline/foxglove/server.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/queued_sink.h"

namespace mocap::publish {

namespace {

constexpr int kFrameQueueDepth = 4;  // frames waiting for the encoder: the newest matter
// The 3D channels (/tf, /markers, /joints, /bodies) at most this often by default: a display's
// rate. Every frame at 100 fps tripled the loopback traffic and its kernel (softirq) work,
// which runs above the real-time stages (docs/performance.md, 2026-12-02).
constexpr int kDefaultMaxRateHz = 50;

std::int64_t clock_ns(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return std::int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
}

class FoxgloveSink final : public QueuedSink {
 public:
  FoxgloveSink(foxglove::FoxgloveScene scene, std::unique_ptr<foxglove::Server> server,
               std::string url, int max_rate_hz)
      : QueuedSink(kFrameQueueDepth),
        scene_(std::move(scene)),
        server_(std::move(server)),
        url_(std::move(url)),
        realtime_minus_monotonic_ns_(clock_ns(CLOCK_REALTIME) - clock_ns(CLOCK_MONOTONIC)),
        // 10 % slack, so that frame-period jitter does not halve the rate
        min_period_ns_(900'000'000 / max_rate_hz) {}
  ~FoxgloveSink() override {
    stop();  // the worker first (it calls the server), then the server
    server_->stop();
  }

  const char* name() const noexcept override { return "foxglove"; }
  std::string notice() const override { return "foxglove: live view on " + url_; }
  OutputCounters counters() const noexcept override {
    OutputCounters c = QueuedSink::counters();
    c.dropped += server_->counters().messages_dropped;
    return c;
  }

 protected:
  void encode(const FrameResult& frame) override {
    const std::int64_t stamp_ns = frame.joints.capture_ns + realtime_minus_monotonic_ns_;
    const auto ts = static_cast<std::uint64_t>(stamp_ns > 0 ? stamp_ns : 0);
    // Capture time, so a replay runs at its own pace; a jump back (restart) sends at once.
    const bool scene_due = frame.joints.capture_ns - last_scene_ns_ >= min_period_ns_ ||
                           frame.joints.capture_ns < last_scene_ns_;
    if (scene_due) send_scene(frame, ts, stamp_ns);
    // The aiming overlays, at a low rate.
    if (frame.joints.capture_ns - last_overlay_ns_ < foxglove::kBlobOverlayPeriodNs &&
        frame.joints.capture_ns >= last_overlay_ns_)
      return;
    bool sent = false;
    for (std::size_t c = 0; c < scene_.cameras.size(); ++c) {
      const std::uint32_t channel = foxglove::kChannelBlobsFirst + static_cast<std::uint32_t>(c);
      if (!server_->has_subscribers(channel)) continue;
      server_->broadcast(channel, ts,
                         std::make_shared<const std::string>(foxglove::encode_blob_overlay(
                             scene_, frame, static_cast<int>(c), stamp_ns)));
      sent = true;
    }
    if (sent) last_overlay_ns_ = frame.joints.capture_ns;
  }

 private:
  void send_scene(const FrameResult& frame, std::uint64_t ts, std::int64_t stamp_ns) {
    using foxglove::kChannelJoints, foxglove::kChannelMarkers, foxglove::kChannelTf;
    last_scene_ns_ = frame.joints.capture_ns;
    if (server_->has_subscribers(kChannelTf)) {
      server_->broadcast(kChannelTf, ts,
                         std::make_shared<const std::string>(
                             foxglove::encode_frame_transforms(scene_, frame, stamp_ns)));
    }
    if (server_->has_subscribers(kChannelMarkers)) {
      server_->broadcast(kChannelMarkers, ts,
                         std::make_shared<const std::string>(
                             foxglove::encode_scene_update(scene_, frame, stamp_ns)));
    }
    if (server_->has_subscribers(kChannelJoints)) {
      server_->broadcast(kChannelJoints, ts,
                         std::make_shared<const std::string>(
                             foxglove::encode_joint_angles(scene_, frame, stamp_ns)));
    }
    if (server_->has_subscribers(foxglove::kChannelBodies)) {
      server_->broadcast(foxglove::kChannelBodies, ts,
                         std::make_shared<const std::string>(
                             foxglove::encode_body_states(scene_, frame, stamp_ns)));
    }
  }

  const foxglove::FoxgloveScene scene_;
  std::unique_ptr<foxglove::Server> server_;
  const std::string url_;
  const std::int64_t realtime_minus_monotonic_ns_;
  const std::int64_t min_period_ns_;              // of the 3D channels
  std::int64_t last_scene_ns_ = INT64_MIN / 2;    // capture time of the last 3D messages
  std::int64_t last_overlay_ns_ = INT64_MIN / 2;  // capture time of the last overlays sent
};

// A positive integer option (max_clients, client_queue) or the default.
Expected<foxglove::ServerOptions> options_of(const OutputRequest& r) {
  if (r.values.size() != 1) {
    return make_error(
        r.where, "",
        "expected one [ADDRESS:]PORT, got " + std::to_string(r.values.size()) + " values");
  }
  foxglove::ServerOptions o;
  if (auto a = foxglove::parse_listen_address(r.values[0], r.where, o); !a) return a.error();
  auto clients = r.int_option("max_clients", o.max_clients, 1, 64);
  if (!clients) return clients.error();
  auto queue = r.int_option("client_queue", o.client_queue_depth, 1, 4096);
  if (!queue) return queue.error();
  if (auto rate = r.int_option("max_rate_hz", kDefaultMaxRateHz, 1, 1000); !rate)
    return rate.error();
  o.max_clients = *clients;
  o.client_queue_depth = *queue;
  return o;
}

Expected<void> check_foxglove(const OutputRequest& r) {
  auto o = options_of(r);
  if (!o) return o.error();
  return {};
}

Expected<OutputCreated> create_foxglove(const OutputRequest& r, const OutputContext& ctx) {
  auto o = options_of(r);
  if (!o) return o.error();
  if (ctx.targets == nullptr) return make_error(r.where, "", "needs the targets (none given)");
  auto scene = foxglove::make_scene(*ctx.targets, ctx.model, ctx.rig);
  if (!scene) return scene.error();
  auto server = foxglove::Server::create(*o, foxglove::live_view_channels(*scene));
  if (!server) {  // "foxglove: ADDR:PORT: cannot listen: ..." -> under the request's name
    std::string m = server.error().message;
    if (m.rfind("foxglove: ", 0) == 0) m.erase(0, 10);
    return make_error(r.where, "", m);
  }
  const std::string host =
      o->address.find(':') != std::string::npos ? "[" + o->address + "]" : o->address;
  const std::string url = "ws://" + host + ":" + std::to_string((*server)->port());
  (*server)->start();
  auto rate = r.int_option("max_rate_hz", kDefaultMaxRateHz, 1, 1000);
  if (!rate) return rate.error();
  auto sink = std::make_unique<FoxgloveSink>(std::move(*scene), std::move(*server), url, *rate);
  if (auto s = sink->start(); !s) return s.error();
  OutputCreated out;
  out.notice = sink->notice();
  out.sink = std::move(sink);
  return out;
}

}  // namespace

extern const OutputKind kFoxgloveOutput;
const OutputKind kFoxgloveOutput{
    "foxglove", "Foxglove WebSocket live view on [ADDRESS:]PORT (docs/foxglove.md)",
    "max_clients client_queue max_rate_hz", &check_foxglove, &create_foxglove};

}  // namespace mocap::publish
