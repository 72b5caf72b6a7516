// Design: see identify_stage.h.
#include "pipeline/identify_stage.h"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "pipeline/frame_result_builder.h"

namespace mocap::pipeline {

Expected<std::unique_ptr<IdentifyStage>> IdentifyStage::create(std::uint32_t input_depth,
                                                               StageContext& context,
                                                               FrameProcessor& processor,
                                                               rt::SlotPool<MsgSlot>& out) {
  const PipelineOptions& o = context.options();
  const std::int64_t tolerance = o.pair_by == PairBy::kTimestamp ? o.pair_tolerance_us * 1000 : 0;
  hal::PairerConfig pc{tolerance, input_depth, processor.camera_count(), {}};
  pc.silent_after_ns = o.silent_after_ns;
  auto pairer = hal::FramePairer::create(pc);
  if (!pairer) return pairer.error();
  std::unique_ptr<IdentifyStage> s(
      new IdentifyStage(context, processor, out, std::move(pairer).value()));
  for (int c = 0; c < s->cameras_; ++c) {
    const detect::BlobList proto = s->frame_->blobs[static_cast<std::size_t>(c)];
    const UndistortedStore proto_undistorted =
        static_cast<std::size_t>(c) < s->frame_->undistorted.size()
            ? s->frame_->undistorted[static_cast<std::size_t>(c)]
            : UndistortedStore{};
    auto pool = rt::SlotPool<BlobSlot>::create(input_depth + 2, [&](std::uint32_t) {
      BlobSlot slot;
      slot.blobs = proto;                    // the detector's capacity: no allocation when filled
      slot.undistorted = proto_undistorted;  // the same, for the detect stage's undistortion
      return slot;
    });
    if (!pool) return pool.error();
    s->inputs_.push_back(std::make_unique<rt::SlotPool<BlobSlot>>(std::move(pool).value()));
  }
  return s;
}

IdentifyStage::IdentifyStage(StageContext& context, FrameProcessor& processor,
                             rt::SlotPool<MsgSlot>& out, hal::FramePairer pairer)
    : context_(context),
      processor_(processor),
      out_(out),
      cameras_(processor.camera_count()),
      pairer_(std::move(pairer)),
      frame_(std::make_unique<FrameOutput>(processor.make_output())) {}

void IdentifyStage::count_unpaired(std::uint64_t sequence) noexcept {
  if (!counting_) {
    const std::uint64_t first = context_.first_sequence_plus_one();
    next_sequence_ = first == 0 ? sequence : first - 1;
    counting_ = true;
  }
  if (sequence >= next_sequence_) {
    counters_.frames_unpaired.add(sequence - next_sequence_);
    next_sequence_ = sequence + 1;
  }
}

void IdentifyStage::release_set(const hal::FramePair& set) noexcept {
  for (int c = 0; c < cameras_; ++c) {
    if (set.cam[c].handle != hal::kAbsentHandle)
      inputs_[static_cast<std::size_t>(c)]->release(set.cam[c].handle);
  }
}

int IdentifyStage::first_present(const hal::FramePair& set) const noexcept {
  for (int c = 0; c < cameras_; ++c) {
    if (set.cam[c].handle != hal::kAbsentHandle) return c;
  }
  return 0;  // unreachable: a set holds the frame that completed it
}

void IdentifyStage::run() noexcept {
  context_.loop_start(StageId::kIdentify);
  rt::Doorbell& bell = context_.bell(StageId::kIdentify);
  auto on_drop = [this](int c, const hal::PairEntry& e) {
    rt::SlotPool<BlobSlot>& pool = *inputs_[static_cast<std::size_t>(c)];
    const std::uint64_t sequence = pool[e.handle].sequence;
    pool.release(e.handle);
    context_.retire(sequence);
  };
  const bool by_time = context_.options().pair_by == PairBy::kTimestamp;
  const PipelineOptions& options = context_.options();
  bool have_set = false;
  hal::FramePair set{};
  auto take = [&](const hal::FramePair& p) {
    count_unpaired(sequence_of(p));
    // Catch-up: the older set first while it is fresh, else dropped (options.fresh).
    if (have_set && options.fresh(origin_of(set), monotonic_ns())) {
      process(set);
    } else if (have_set) {  // too old: a newer set is complete
      counters_.skipped.add();
      const std::uint64_t dropped = sequence_of(set);
      release_set(set);
      context_.retire(dropped);
    }
    set = p;
    have_set = true;
  };
  bool done = false;  // this run's input ended and was settled (see settle())
  while (!context_.stopping()) {
    const std::uint32_t seen = bell.snapshot();
    const std::int64_t now = monotonic_ns();
    // The capture's end, and every frame it handed on came out of the detect stages
    // (acquire loads: their blob slots are in the pools now): the pops below are the last.
    const bool last_pops = !done && context_.capture_done() && context_.detect_drained(cameras_);
    hal::FramePair p;
    bool popped = false;
    for (int c = 0; c < cameras_; ++c) {
      rt::SlotPool<BlobSlot>& pool = *inputs_[static_cast<std::size_t>(c)];
      rt::SlotHandle h;
      while (pool.pop(h)) {
        popped = true;
        const std::int64_t key =
            by_time ? pool[h].capture_ns : static_cast<std::int64_t>(pool[h].sequence);
        if (pairer_.push(c, hal::PairEntry{key, h}, p, on_drop, now)) take(p);
      }
    }
    // Silent cameras (camera nodes, PipelineOptions::silent_after_ns): the sets that
    // waited for them long enough complete without them.
    while (pairer_.expire(now, p)) take(p);
    if (!have_set && last_pops && !popped) {
      // No frame will come: the sets that may complete without silent cameras do so
      // now, as if their bounds had passed; the rest are settled.
      while (pairer_.expire(std::numeric_limits<std::int64_t>::max() / 2, p)) take(p);
      if (!have_set) {
        settle();
        done = true;
      }
    }
    if (!have_set) {
      const std::int64_t until_silence = pairer_.next_silence_ns() - now;
      bell.wait(seen, std::clamp<std::int64_t>(until_silence, 1, kIdleWaitNs));
      continue;
    }
    have_set = false;
    process(set);
  }
  context_.loop_end(StageId::kIdentify);
}

void IdentifyStage::process(const hal::FramePair& set) noexcept {
  const std::int64_t t0 = monotonic_ns();
  FrameOutput& out = *frame_;
  for (int c = 0; c < cameras_; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    if (set.cam[c].handle == hal::kAbsentHandle) {  // a silent camera: no frame
      out.blobs[ci].clear();
      out.camera_present[ci] = false;
      continue;
    }
    BlobSlot& slot = (*inputs_[ci])[set.cam[c].handle];
    std::swap(out.blobs[ci], slot.blobs);  // O(1), same capacities: no allocation
    if (ci < out.undistorted.size()) std::swap(out.undistorted[ci], slot.undistorted);
    out.camera_present[ci] = slot.present;
  }
  const int f = first_present(set);
  const BlobSlot& first = (*inputs_[static_cast<std::size_t>(f)])[set.cam[f].handle];
  const std::uint64_t sequence = first.sequence;
  const std::int64_t capture_ns = first.capture_ns;  // the data's time: published as is
  const std::int64_t origin_ns = first.origin_ns;    // the latencies' start
  release_set(set);
  processor_.process_blobs(capture_ns, out);
  library_.stereo.publish(kStereoFields, processor_.stereo_counters());
  if (cameras_ > 2) library_.multiview.publish(kMultiViewFields, processor_.multiview_counters());
  library_.identify.publish(kIdentifyFields, processor_.identify_counters());
  if (const ChainCounters* chain = processor_.chain_counters()) {
    library_.chain.publish(kChainFields, *chain);
    library_.coverage.publish(kCoverageFields, *chain);
  }
  const PipelineOptions& o = context_.options();
  if (o.observer) o.observer->observe(sequence, capture_ns, out);
  rt::SlotHandle m;
  if (out_.acquire(m)) {
    make_frame_result(sequence, capture_ns, processor_.targets(), out, *labelled_, out_[m].frame);
    out_[m].origin_ns = origin_ns;
    if ((out_[m].frame.joints.flags & client::kFlagAllBodiesFound) == 0)
      counters_.without_result.add();
    out_.publish(m);
    context_.note_handed_to_publish();
    context_.bell(StageId::kPublish).ring();
  } else {  // publish holds every slot (stalled sink)
    counters_.no_slot.add();
    context_.retire(sequence);
  }
  const std::int64_t t1 = monotonic_ns();
  work_.record(t1 - t0);
  latency_.record(t1 - origin_ns);
}

void IdentifyStage::settle() noexcept {
  // The sets still pending can never complete: their frames are dropped as the pairer
  // drops a frame another camera has passed (unmatched), and the sequences from the last
  // set taken to the capture's last one are counted as never paired.
  pairer_.flush(
      [this](int c, const hal::PairEntry& e) {
        inputs_[static_cast<std::size_t>(c)]->release(e.handle);
      },
      true);
  const std::uint64_t end = context_.end_sequence();
  if (end > 0) count_unpaired(end);
  context_.set_identify_done();
}

void IdentifyStage::drain() noexcept {
  pairer_.flush([this](int c, const hal::PairEntry& e) {
    inputs_[static_cast<std::size_t>(c)]->release(e.handle);
  });
  for (auto& pool : inputs_) {
    rt::SlotHandle h;
    while (pool->pop(h)) pool->release(h);
  }
}

void IdentifyStage::report(rt::CounterReport& out) const {
  const hal::PairerCounters& pc = pairer_.counters();
  for (int c = 0; c < cameras_; ++c)
    out.emplace_back(rt::counter_name("pair_unmatched_cam#", c), pc.unmatched[c].get());
  for (int c = 0; c < cameras_; ++c)
    out.emplace_back(rt::counter_name("pair_overflow_cam#", c), pc.overflow[c].get());
  if (context_.options().has_silent_bounds()) {  // camera nodes: silent cameras
    for (int c = 0; c < cameras_; ++c)
      out.emplace_back(rt::counter_name("pair_silent_cam#", c), pc.silent[c].get());
    for (int c = 0; c < cameras_; ++c)
      out.emplace_back(rt::counter_name("pair_absent_cam#", c), pc.absent[c].get());
    out.emplace_back("frames_without_silent_cameras", pc.partial.get());
  }
  counters_.group.report(cameras_, out);
  for (std::size_t i = 0; i < kStereoFields.size(); ++i)
    out.emplace_back(std::string("stereo_") + kStereoFields[i].name, library_.stereo.get(i));
  for (std::size_t i = 0; cameras_ > 2 && i < kMultiViewFields.size(); ++i) {
    out.emplace_back(std::string("multiview_") + kMultiViewFields[i].name,
                     library_.multiview.get(i));
  }
  for (std::size_t i = 0; i < kIdentifyFields.size(); ++i)
    out.emplace_back(std::string("identify_") + kIdentifyFields[i].name, library_.identify.get(i));
  if (!processor_.has_model()) return;
  for (std::size_t i = 0; i < kChainFields.size(); ++i)
    out.emplace_back(std::string("chain_") + kChainFields[i].name, library_.chain.get(i));
  const auto& joints = processor_.model().joints;
  for (std::size_t j = 0; j < joints.size() && 2 * j + 1 < kCoverageFields.size(); ++j) {
    out.emplace_back("coverage_" + joints[j].name + "_poses", library_.coverage.get(2 * j));
    out.emplace_back("coverage_" + joints[j].name + "_chain", library_.coverage.get(2 * j + 1));
  }
}

}  // namespace mocap::pipeline
