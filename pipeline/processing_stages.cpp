// Design: see pipeline.h. The processing stages after the capture (hot path: noexcept,
// allocation-free, lock-free, no logging; each counter has one writer thread):
//   detect c : the newest frame of camera c -> its blobs in a blob slot (drop-oldest);
//   identify : matches every camera's blob slot of a sequence (hal::FramePairer), then
//              pairs + N-view merge + identification + angles
//              (FrameProcessor::process_blobs) into a message slot (drop-oldest pairs);
//   publish  : the newest message to every sink, then the sequence is retired.
#include <utility>

#include "pipeline/pipeline.h"

namespace mocap::pipeline {

void Pipeline::detect_loop(int camera) noexcept {
  const StageId id = StageId::detect(camera);
  if (options_.hooks) options_.hooks->on_loop_start(id);
  const auto c = static_cast<std::size_t>(camera);
  rt::SpscRing<hal::Frame>& in = *to_detect_[c];
  rt::SpscRing<hal::Frame>& back = *returned_[c];
  rt::SlotPool<BlobSlot>& pool = *blob_pools_[c];
  Doorbell& bell = bells_[index(id)];
  Counters& k = *counters_;
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    hal::Frame f;
    if (!in.try_pop(f)) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    hal::Frame newer;
    while (in.try_pop(newer)) {  // drop-oldest: work on the freshest frame
      back.try_push(f);          // cannot fail: holds every camera buffer
      k.detect_skipped[c].add();
      f = newer;
    }
    rt::SlotHandle h;
    if (!pool.acquire(h)) {  // identify holds every slot (stalled): drop
      k.detect_no_slot[c].add();
      back.try_push(f);
      continue;
    }
    const std::int64_t t0 = monotonic_ns();
    BlobSlot& slot = pool[h];
    slot.blobs.clear();
    slot.present = !f.missing && !f.image.empty();
    if (slot.present) {
      processor_.detect_camera(camera, f.image, slot.blobs);
      Counters::DetectLibrary& lib = k.detect_library[c];
      lib.blobs.add(slot.blobs.size());
      lib.detector.publish(kDetectorFields, processor_.detector_counters(camera));
    }
    slot.sequence = f.sequence;
    slot.capture_ns = f.timestamp_ns;
    const std::int64_t capture_ns = f.timestamp_ns;  // the slot is identify's once published
    back.try_push(f);                                // the image is no longer needed
    pool.publish(h);
    bells_[index(StageId::kIdentify)].ring();
    const std::int64_t t1 = monotonic_ns();
    lat_->detect_work[c].record(t1 - t0);
    lat_->detect[c].record(t1 - capture_ns);
  }
  if (options_.hooks) options_.hooks->on_loop_end(id);
}

void Pipeline::identify_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kIdentify);
  Doorbell& bell = bells_[index(StageId::kIdentify)];
  Counters& k = *counters_;
  hal::FramePairer& pairer = *pairer_;
  FrameOutput& out = *out_;
  auto on_drop = [&](int c, const hal::PairEntry& e) {
    rt::SlotPool<BlobSlot>& pool = *blob_pools_[static_cast<std::size_t>(c)];
    const std::uint64_t sequence = pool[e.handle].sequence;
    pool.release(e.handle);
    retire(sequence);
  };
  const bool by_time = options_.pair_by == PairBy::kTimestamp;
  std::uint64_t next_sequence = 0;  // the first sequence not yet accounted for
  bool counting = false;
  bool have_pair = false;
  hal::FramePair pair{};
  // Sequences between two consecutive pairs never formed a pair (dropped by a camera, the
  // capture, a detector or the pairer): counted once each, when the next pair forms
  // (pairs form in increasing sequence order). Pairs dropped later are counted by the
  // stage that drops them (identify_skipped, identify_no_slot, publish_skipped).
  auto count_unpaired = [&](std::uint64_t sequence) {
    if (!counting) {
      // acquire: see on_frame_received(); the capture stored it before any push.
      const std::uint64_t first = first_sequence_.load(std::memory_order_acquire);
      next_sequence = first == 0 ? sequence : first - 1;
      counting = true;
    }
    if (sequence >= next_sequence) {
      k.frames_unpaired.add(sequence - next_sequence);
      next_sequence = sequence + 1;
    }
  };
  const int n = camera_count();
  auto release_set = [&](const hal::FramePair& set) {  // every camera's slot of a set
    for (int c = 0; c < n; ++c)
      blob_pools_[static_cast<std::size_t>(c)]->release(set.cam[c].handle);
  };
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    for (int c = 0; c < n; ++c) {
      rt::SlotPool<BlobSlot>& pool = *blob_pools_[static_cast<std::size_t>(c)];
      rt::SlotHandle h;
      while (pool.pop(h)) {
        hal::FramePair p;
        const std::int64_t key =
            by_time ? pool[h].capture_ns : static_cast<std::int64_t>(pool[h].sequence);
        const hal::PairEntry e{key, h};
        if (!pairer.push(c, e, p, on_drop)) continue;
        count_unpaired((*blob_pools_[0])[p.cam[0].handle].sequence);
        if (have_pair) {  // drop-oldest: a newer set is complete
          k.identify_skipped.add();
          const std::uint64_t dropped = (*blob_pools_[0])[pair.cam[0].handle].sequence;
          release_set(pair);
          retire(dropped);
        }
        pair = p;
        have_pair = true;
      }
    }
    if (!have_pair) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    have_pair = false;
    const std::int64_t t0 = monotonic_ns();
    for (int c = 0; c < n; ++c) {
      const auto ci = static_cast<std::size_t>(c);
      BlobSlot& slot = (*blob_pools_[ci])[pair.cam[c].handle];
      std::swap(out.blobs[ci], slot.blobs);  // O(1), same capacities: no allocation
      out.camera_present[ci] = slot.present;
    }
    const BlobSlot& first = (*blob_pools_[0])[pair.cam[0].handle];
    const std::uint64_t sequence = first.sequence;
    const std::int64_t capture_ns = first.capture_ns;
    release_set(pair);
    processor_.process_blobs(capture_ns, out);
    k.identify_library.stereo.publish(kStereoFields, processor_.stereo_counters());
    k.identify_library.identify.publish(kIdentifyFields, processor_.identify_counters());
    if (const ChainCounters* chain = processor_.chain_counters()) {
      k.identify_library.chain.publish(kChainFields, *chain);
      k.identify_library.coverage.publish(kCoverageFields, *chain);
    }
    if (options_.observer) options_.observer->observe(sequence, capture_ns, out);
    rt::SlotHandle m;
    if (msg_pool_->acquire(m)) {
      make_frame_result(sequence, capture_ns, processor_.targets(), out, (*msg_pool_)[m].frame);
      if (((*msg_pool_)[m].frame.joints.flags & client::kFlagAllBodiesFound) == 0)
        k.frames_without_result.add();
      msg_pool_->publish(m);
      bells_[index(StageId::kPublish)].ring();
    } else {  // publish holds every slot (stalled sink)
      k.identify_no_slot.add();
      retire(sequence);
    }
    const std::int64_t t1 = monotonic_ns();
    lat_->identify_work.record(t1 - t0);
    lat_->identify.record(t1 - capture_ns);
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kIdentify);
}

void Pipeline::publish_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kPublish);
  Doorbell& bell = bells_[index(StageId::kPublish)];
  Counters& k = *counters_;
  rt::SlotPool<MsgSlot>& pool = *msg_pool_;
  std::uint64_t skipped_seen = 0;
  std::int64_t prev_publish_ns = 0;
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    rt::SlotHandle h;
    if (!pool.pop_latest(h)) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    if (pool.skipped() != skipped_seen) {  // older messages replaced by this one
      k.publish_skipped.add(pool.skipped() - skipped_seen);
      skipped_seen = pool.skipped();
    }
    publish::FrameResult& frame = pool[h].frame;
    const client::JointsMessage& msg = frame.joints;
    const std::int64_t t0 = monotonic_ns();
    frame.joints.publish_ns = t0;
    std::int64_t t1 = t0;
    for (std::size_t i = 0; i < sinks_.size(); ++i) {
      if (!sinks_[i]->publish(frame)) k.sink_failures.add();
      const std::int64_t t = monotonic_ns();  // vDSO clock read, no syscall
      lat_->sink_work_each[i].record(t - t1);
      t1 = t;
    }
    const std::uint64_t sequence = msg.sequence;
    if (prev_publish_ns != 0) {  // publish period, exponential average over ~16 frames
      const std::int64_t ema = publish_period_ns_.load(std::memory_order_relaxed);
      const std::int64_t dt = t0 - prev_publish_ns;
      // relaxed: single writer; health() only wants a recent, untorn value.
      publish_period_ns_.store(ema == 0 ? dt : ema + (dt - ema) / 16, std::memory_order_relaxed);
    }
    prev_publish_ns = t0;
    lat_->sink_work.record(t1 - t0);
    lat_->publish.record(t0 - msg.capture_ns);
    pool.release(h);
    // relaxed, then release: a reader that sees the new count (acquire) sees this time.
    last_publish_ns_.store(t0, std::memory_order_relaxed);
    published_.fetch_add(1, std::memory_order_release);
    retire(sequence);
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kPublish);
}

}  // namespace mocap::pipeline
