// Design: see node_link.h.
#include "pipeline/node/node_link.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "core/clock.h"

namespace mocap::node {

Expected<std::shared_ptr<NodeLink>> NodeLink::create(std::uint32_t domain_id, double wait_s,
                                                     bool realtime, std::int64_t trigger_lead_ns) {
  if (trigger_lead_ns < 0) return make_error("mocap run", "node.trigger_lead_us", "must be >= 0");
  std::shared_ptr<NodeLink> l(new NodeLink());
  auto d = NodeDomain::open(domain_id, "mocap run: nodes", realtime);
  if (!d) return d.error();
  l->domain_ = std::move(d).value();
  auto r = l->domain_.reader(l->domain_.blob_topic(), "mocap run: mocap/blobs");
  if (!r) return r.error();
  l->reader_ = *r;
  auto w = l->domain_.writer(l->domain_.trigger_topic(), "mocap run: mocap/trigger");
  if (!w) return w.error();
  l->writer_ = *w;
  auto ring = rt::SpscRing<Posted>::create(1024);
  if (!ring) return ring.error();
  l->triggers_ = std::make_unique<rt::SpscRing<Posted>>(std::move(ring).value());
  l->trigger_lead_ns_ = trigger_lead_ns;
  l->wait_s_ = wait_s;
  l->realtime_ = realtime;
  return l;
}

NodeLink::~NodeLink() {
  users_ = 1;
  stop();
}

Expected<int> NodeLink::add_camera(const std::string& node, const std::string& camera,
                                   std::uint32_t slots, int max_blobs) {
  for (const Camera& c : cameras_) {
    if (c.node == node && c.camera == camera)
      return make_error("cameras", node + "/" + camera, "listed twice");
  }
  int node_index = -1;
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    if (nodes_[i]->name == node) node_index = static_cast<int>(i);
  if (node_index < 0) {
    nodes_.push_back(std::make_unique<NodeStats>());
    nodes_.back()->name = node;
    node_index = static_cast<int>(nodes_.size() - 1);
  }
  cameras_.push_back(Camera{node, camera, node_index});
  auto pool = rt::SlotPool<Received>::create(slots, [&](std::uint32_t) {
    Received r;
    r.blobs = detect::BlobList(max_blobs);
    return r;
  });
  if (!pool) return pool.error();
  inboxes_.push_back(std::make_unique<rt::SlotPool<Received>>(std::move(pool).value()));
  full_.push_back(std::make_unique<rt::Counter>());
  spare_.push_back(-1);
  return static_cast<int>(cameras_.size() - 1);
}

Expected<void> NodeLink::start() {
  if (users_++ > 0) return {};
  stop_.store(false, std::memory_order_relaxed);  // no thread runs yet
  next_trigger_ = 0;
  received_end_.store(0, std::memory_order_relaxed);  // no thread runs yet
  const int priority = realtime_ ? kDdsFifoPriority : 0;
  auto b =
      rt::start_thread(rt::ThreadSpec{"mocap-ntrig", -1, priority}, [this] { trigger_loop(); });
  if (!b) return b.error();
  trigger_thread_ = std::move(b).value();
  // The messages are taken where Cyclone delivers them (its receive thread): no hop.
  dds_listener_t* l = dds_create_listener(this);
  dds_lset_data_available(l, &NodeLink::on_data);
  const dds_return_t rc = dds_set_listener(reader_, l);
  dds_delete_listener(l);
  if (rc < 0) {
    users_ = 1;
    stop();
    return make_error("mocap run", "mocap/blobs", "cannot set the DDS listener");
  }
  notice_.clear();
  if (!wait_for_nodes(wait_s_)) {
    notice_ = "not every node was discovered within " + std::to_string(wait_s_) +
              " s: their cameras count as missing until they appear";
  }
  if (!trigger_thread_.setup().note.empty())
    notice_ += (notice_.empty() ? "" : "; ") + trigger_thread_.setup().note;
  return {};
}

bool NodeLink::wait_for_nodes(double wait_s) noexcept {
  const auto want = static_cast<std::uint32_t>(nodes_.size());
  const std::int64_t deadline = monotonic_ns() + static_cast<std::int64_t>(wait_s * 1e9);
  for (;;) {
    dds_subscription_matched_status_t in{};
    dds_publication_matched_status_t out{};
    (void)dds_get_subscription_matched_status(reader_, &in);
    (void)dds_get_publication_matched_status(writer_, &out);
    if (in.current_count >= want && out.current_count >= want) {
      // Discovery is symmetric but not simultaneous: give the far ends a moment too.
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      return true;
    }
    if (monotonic_ns() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void NodeLink::stop() noexcept {
  if (users_ == 0 || --users_ > 0) return;
  // release: the threads' acquire loads see the stop.
  stop_.store(true, std::memory_order_release);
  trigger_bell_.ring();
  // Returns once a listener call in progress has returned; none is made after.
  (void)dds_set_listener(reader_, nullptr);
  if (trigger_thread_.joinable()) trigger_thread_.join();
}

void NodeLink::trigger(std::uint64_t number, std::int64_t at_ns) noexcept {
  if (number < next_trigger_) return;  // another camera posted it
  next_trigger_ = number + 1;
  (void)triggers_->try_push(Posted{number, at_ns});  // 1024 deep: full only when DDS stalls
  trigger_bell_.ring();
}

void NodeLink::trigger_loop() noexcept {
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = trigger_bell_.snapshot();
    Posted p;
    if (!triggers_->try_pop(p)) {
      trigger_bell_.wait(seen, 10'000'000);
      continue;
    }
    const std::int64_t sent = realtime_ns();
    // The instant on CLOCK_REALTIME, the clock the nodes share (PTP).
    const std::int64_t fire = p.at_ns != 0 ? p.at_ns + (sent - monotonic_ns()) : 0;
    fire_rt_[p.number % std::size(fire_rt_)].store(fire, std::memory_order_relaxed);
    const mocap_node_Trigger t{p.number, sent, fire};
    if (dds_write(writer_, &t) >= 0) triggers_sent_.add();
  }
}

void NodeLink::on_data(dds_entity_t reader, void* self) noexcept {
  static_cast<NodeLink*>(self)->take_all(reader);
}

void NodeLink::take_all(dds_entity_t reader) noexcept {
  constexpr int kBatch = 16;
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  for (;;) {
    const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n <= 0) break;
    for (dds_return_t i = 0; i < n; ++i) {
      if (infos[i].valid_data) on_sample(*static_cast<const mocap_node_BlobFrame*>(samples[i]));
    }
    (void)dds_return_loan(reader, samples, n);
    samples[0] = nullptr;  // the next take loans again
  }
}

void NodeLink::on_sample(const mocap_node_BlobFrame& s) noexcept {
  const std::int64_t t3 = realtime_ns();
  const std::int64_t now = monotonic_ns();
  WireHeader h;
  from_sample(s, h);
  // The names first (bounded, NUL-terminated): the message is counted against its node.
  int k = -1;
  if (valid_name(h.node) && valid_name(h.camera)) {
    for (std::size_t i = 0; i < cameras_.size(); ++i) {
      if (cameras_[i].node == h.node && cameras_[i].camera == h.camera) k = static_cast<int>(i);
    }
  }
  if (k < 0) {
    unknown_.add();
    return;
  }
  NodeStats& node =
      *nodes_[static_cast<std::size_t>(cameras_[static_cast<std::size_t>(k)].node_index)];
  node.messages.add();
  rt::SlotPool<Received>& pool = *inboxes_[static_cast<std::size_t>(k)];
  const auto ki = static_cast<std::size_t>(k);
  rt::SlotHandle slot;
  if (spare_[ki] >= 0) {  // the slot a malformed message left
    slot = static_cast<rt::SlotHandle>(spare_[ki]);
  } else if (!pool.acquire(slot)) {  // the capture thread has not taken the last slot_count
    full_[ki]->add();
    return;
  }
  spare_[ki] = -1;
  Received& r = pool[slot];
  const WireError e = decode_frame(h, s.blobs._buffer, s.blobs._length, r.blobs);
  if (e != WireError::kOk) {
    (e == WireError::kOversized ? node.oversized : node.malformed).add();
    spare_[ki] = static_cast<std::int64_t>(slot);  // kept for the next message (SPSC roles)
    return;
  }
  r.header = h;
  r.received_ns = now;
  estimate_offset(node, h, t3);
  if (h.sent_ns != 0) transit_.record(t3 - h.sent_ns);
  if (h.trigger_sent_ns != 0 && h.trigger_received_ns != 0 && h.sent_ns != 0) {
    trigger_leg_.record(h.trigger_received_ns - h.trigger_sent_ns);
    // The node's leg starts when the trigger took effect: on arrival, or at its instant.
    const std::int64_t fire =
        fire_rt_[h.frame_number % std::size(fire_rt_)].load(std::memory_order_relaxed);
    node_work_.record(h.sent_ns - std::max(h.trigger_received_ns, fire));
  }
  if ((h.flags & kWireEndOfStream) == 0 &&
      h.frame_number + 1 > received_end_.load(std::memory_order_relaxed))  // single writer
    received_end_.store(h.frame_number + 1, std::memory_order_release);    // see received_end()
  pool.publish(slot);
  bell_.ring();
}

void NodeLink::estimate_offset(NodeStats& n, const WireHeader& h, std::int64_t t3) noexcept {
  std::int64_t offset = h.sent_ns - t3;  // one way: includes the transit
  std::int64_t rtt = -1;
  if (h.trigger_sent_ns != 0 && h.trigger_received_ns != 0 && h.sent_ns != 0) {
    rtt = (t3 - h.trigger_sent_ns) - (h.sent_ns - h.trigger_received_ns);
    offset = ((h.trigger_received_ns - h.trigger_sent_ns) + (h.sent_ns - t3)) / 2;
  }
  // The best sample of the current window of 256 (the smallest round trip; one-way
  // samples only while no round trip is known) is the estimate, published as it improves.
  const bool better =
      n.window_count == 0 || (rtt >= 0 && (n.window_best_rtt < 0 || rtt < n.window_best_rtt));
  if (better) {
    n.window_best_rtt = rtt;
    n.window_offset = offset;
    // relaxed: independent statistics; readers want recent, untorn values.
    n.offset_ns.store(offset, std::memory_order_relaxed);
    n.round_trip_ns.store(rtt, std::memory_order_relaxed);
  }
  if (++n.window_count >= 256) n.window_count = 0;  // the next sample starts a new window
}

std::string NodeLink::report() const {
  std::string out;
  for (const auto& n : nodes_) {
    char line[320];
    std::snprintf(line, sizeof line,
                  "node %s: messages %llu, malformed %llu, oversized %llu, clock offset %+.1f us "
                  "(round trip %.1f us)\n",
                  n->name.c_str(), static_cast<unsigned long long>(n->messages.get()),
                  static_cast<unsigned long long>(n->malformed.get()),
                  static_cast<unsigned long long>(n->oversized.get()),
                  static_cast<double>(n->offset_ns.load(std::memory_order_relaxed)) / 1e3,
                  static_cast<double>(n->round_trip_ns.load(std::memory_order_relaxed)) / 1e3);
    out += line;
  }
  if (unknown_.get() > 0)
    out += "nodes: " + std::to_string(unknown_.get()) + " messages of unknown cameras dropped\n";
  return out;
}

}  // namespace mocap::node
