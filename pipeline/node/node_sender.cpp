// Design: see node_sender.h.
#include "pipeline/node/node_sender.h"

#include <algorithm>

#include "core/clock.h"

namespace mocap::node {

Expected<std::unique_ptr<NodeSender>> NodeSender::create(std::uint32_t domain_id,
                                                         const std::vector<bool>& central,
                                                         int queue_depth, bool realtime) {
  const int n = static_cast<int>(central.size());
  if (n < 1 || n > kMaxNodeCameras)
    return make_error("mocap node", "cameras", "1.." + std::to_string(kMaxNodeCameras));
  std::unique_ptr<NodeSender> s(new NodeSender());
  auto d = NodeDomain::open(domain_id, "mocap node", realtime, true);  // batched: send_pending
  if (!d) return d.error();
  s->domain_ = std::move(d).value();
  auto w = s->domain_.writer(s->domain_.blob_topic(), "mocap node: mocap/blobs");
  if (!w) return w.error();
  s->writer_ = *w;
  auto r = s->domain_.reader(s->domain_.trigger_topic(), "mocap node: mocap/trigger");
  if (!r) return r.error();
  s->trigger_reader_ = *r;
  s->central_ = central;
  s->realtime_ = realtime;
  for (int c = 0; c < n; ++c) {
    auto q = rt::DropOldestQueue<WireFrame>::create(queue_depth);
    if (!q) return q.error();
    s->queues_.push_back(std::move(q).value());
    auto ring = rt::SpscRing<TriggerStamp>::create(1024);
    if (!ring) return ring.error();
    s->triggers_.push_back(std::make_unique<rt::SpscRing<TriggerStamp>>(std::move(ring).value()));
  }
  return s;
}

NodeSender::~NodeSender() { stop(false); }

Expected<void> NodeSender::start() {
  stop_.store(false, std::memory_order_relaxed);  // no thread runs yet
  notes_.clear();
  const int priority = realtime_ ? kSenderFifoPriority : 0;
  auto a = rt::start_thread(rt::ThreadSpec{"mocap-nsend", -1, priority}, [this] { send_loop(); });
  if (!a) return a.error();
  send_thread_ = std::move(a).value();
  if (!send_thread_.setup().note.empty()) notes_.push_back(send_thread_.setup().note);
  // The triggers are taken where Cyclone delivers them (its receive thread): no hop.
  dds_listener_t* l = dds_create_listener(this);
  dds_lset_data_available(l, &NodeSender::on_triggers);
  const dds_return_t rc = dds_set_listener(trigger_reader_, l);
  dds_delete_listener(l);
  if (rc < 0) {
    stop(false);
    return make_error("mocap node", "mocap/trigger", "cannot set the DDS listener");
  }
  return {};
}

void NodeSender::stop(bool flush) noexcept {
  // release: the threads' acquire loads see everything queued before the stop.
  stop_.store(true, std::memory_order_release);
  bell_.ring();
  if (send_thread_.joinable()) send_thread_.join();
  // Returns once a listener call in progress has returned; none is made after.
  if (trigger_reader_ > 0) (void)dds_set_listener(trigger_reader_, nullptr);
  if (flush && writer_ > 0) {
    while (send_pending()) {
    }
    (void)dds_wait_for_acks(writer_, DDS_SECS(2));
  }
}

std::uint32_t NodeSender::matched_readers() const noexcept {
  dds_publication_matched_status_t st{};
  if (writer_ <= 0 || dds_get_publication_matched_status(writer_, &st) < 0) return 0;
  return st.current_count;
}

bool NodeSender::send_pending() noexcept {
  bool any = false;
  for (auto& q : queues_) {
    while (const WireFrame* f = q->front()) {
      mocap_node_BlobFrame s{};
      to_sample(f->header, s);
      s.sent_ns = realtime_ns();
      s.realtime_offset_ns = s.sent_ns - monotonic_ns();
      s.blobs._maximum = s.blobs._length =
          static_cast<std::uint32_t>(f->header.blob_count * kBlobRecordBytes);
      s.blobs._buffer = const_cast<std::uint8_t*>(f->blobs);  // DDS only reads it
      s.blobs._release = false;
      if (dds_write(writer_, &s) < 0) {
        write_errors_.add();
      } else {
        sent_.add();
      }
      q->release();
      any = true;
    }
  }
  // The domain batches the writes (NodeDomain::open): what was written leaves now,
  // together, in as few datagrams as fit (one per node and trigger on loopback).
  if (any) dds_write_flush(writer_);
  return any;
}

void NodeSender::send_loop() noexcept {
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = bell_.snapshot();
    if (!send_pending()) bell_.wait(seen, 10'000'000);
  }
}

FireInstant fire_instant(std::int64_t fire_ns, std::int64_t sent_ns, std::int64_t now_rt,
                         std::int64_t now_mono) noexcept {
  FireInstant f;
  if (fire_ns == 0) return f;  // not scheduled: at once
  std::int64_t wait = fire_ns - now_rt;
  if (wait <= 0) {
    f.late = true;
    return f;
  }
  // The central's lead, on its own clock alone: never wait longer than that after the
  // arrival (a hostile or broken lead: at most kMaxTriggerLeadUs).
  const std::int64_t max_wait =
      std::clamp<std::int64_t>(fire_ns - sent_ns, 0, kMaxTriggerLeadUs * 1000);
  if (wait > max_wait) {
    wait = max_wait;
    f.unsynced = true;
  }
  f.mono_ns = now_mono + wait;
  return f;
}

void NodeSender::on_triggers(dds_entity_t reader, void* self) noexcept {
  static_cast<NodeSender*>(self)->take_triggers(reader);
}

void NodeSender::take_triggers(dds_entity_t reader) noexcept {
  constexpr int kBatch = 32;
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  for (;;) {
    const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n <= 0) break;
    const std::int64_t now = realtime_ns();
    const std::int64_t mono = monotonic_ns();
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* t = static_cast<const mocap_node_Trigger*>(samples[i]);
      triggers_in_.add();
      const FireInstant fire = fire_instant(t->fire_ns, t->sent_ns, now, mono);
      if (fire.late) triggers_late_.add();
      if (fire.unsynced) triggers_unsynced_.add();
      for (std::size_t c = 0; c < central_.size(); ++c) {
        if (central_[c] &&
            !triggers_[c]->try_push(TriggerStamp{t->trigger_number, t->sent_ns, now, fire.mono_ns}))
          triggers_dropped_.add();
      }
    }
    (void)dds_return_loan(reader, samples, n);
    samples[0] = nullptr;  // the next take loans again
    // Every camera's trigger first, then one ring: a woken worker finds them all.
    trigger_bell_.ring(trigger_wakeups_);
  }
}

}  // namespace mocap::node
