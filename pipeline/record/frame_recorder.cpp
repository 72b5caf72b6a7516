// Design: see frame_recorder.h.
#include "pipeline/record/frame_recorder.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "formats/recording.h"

namespace mocap::record {

Expected<std::unique_ptr<FrameRecorder>> FrameRecorder::create(const RecorderOptions& o) {
  if (o.slots_per_camera < 2 || !rt::is_power_of_two(o.slots_per_camera) ||
      o.slots_per_camera > 4096) {
    return make_error(
        "mocap record", "--buffer-frames",
        "must be a power of two in 2..4096, got " + std::to_string(o.slots_per_camera));
  }
  const int n = static_cast<int>(o.cameras.size());
  if (n < kMinCameras || n > kMaxCameras || o.camera_names.size() != o.cameras.size()) {
    return make_error("mocap record", "cameras",
                      std::to_string(n) + " cameras (" + std::to_string(o.camera_names.size()) +
                          " names), expected " + std::to_string(kMinCameras) + ".." +
                          std::to_string(kMaxCameras));
  }
  std::size_t max_bytes = 0;
  for (const CameraGeometry& g : o.cameras) {
    if (g.width <= 0 || g.height <= 0)
      return make_error("mocap record", "camera size", "unknown (width or height 0)");
    max_bytes =
        std::max(max_bytes, static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height) *
                                static_cast<std::size_t>(bytes_per_pixel(g.format)));
  }
  if (o.blobs && (o.max_blobs < 1 || o.max_blobs > kMaxBlobFileBlobs))
    return make_error("mocap record", "detection.max_blobs",
                      "must be 1.." + std::to_string(kMaxBlobFileBlobs) + " for --blobs");
  const bool keep = o.blobs && o.keep_images_every > 0;
  auto files = RecordingFiles::open(o.dir, o.camera_names, max_bytes, o.blobs ? 0 : o.byte_budget,
                                    !o.blobs || keep);
  if (!files) return files.error();
  std::unique_ptr<FrameRecorder> r(new FrameRecorder(o, std::move(files).value()));
  if (o.blobs) {
    r->files_.set_sync_interval(o.sync_interval_ns);  // frames.csv as durable as the blobs
    const std::string folder = o.dir + "/blobs";
    if (::mkdir(folder.c_str(), 0755) != 0 && errno != EEXIST)
      return make_error(folder, "", std::string("cannot create: ") + std::strerror(errno));
    for (std::size_t c = 0; c < static_cast<std::size_t>(n); ++c) {
      BlobFileInfo info;
      info.camera = o.camera_names[c];
      info.width = o.cameras[c].width;
      info.height = o.cameras[c].height;
      info.max_blobs = o.max_blobs;
      auto w = BlobFileWriter::create(Recording::blob_file_path(o.dir, info.camera), info,
                                      o.sync_interval_ns, o.byte_budget);
      if (!w) return w.error();
      r->blob_files_.push_back(std::move(w).value());
    }
  }
  hal::PairerConfig pc;
  pc.tolerance = o.pair_by == pipeline::PairBy::kSequence ? 0 : o.pair_tolerance_ns;
  pc.max_pending = o.slots_per_camera;
  pc.cameras = n;
  pc.silent_after_ns = o.silent_after_ns;
  auto pairer = hal::FramePairer::create(pc);
  if (!pairer) return pairer.error();
  r->pairer_.emplace(std::move(pairer).value());
  for (std::size_t c = 0; c < static_cast<std::size_t>(n); ++c) {
    const CameraGeometry& g = o.cameras[c];
    const std::size_t bytes = static_cast<std::size_t>(g.width) *
                              static_cast<std::size_t>(g.height) *
                              static_cast<std::size_t>(bytes_per_pixel(g.format));
    r->slots_[c].resize(o.slots_per_camera);
    for (Slot& s : r->slots_[c]) {
      if (o.blobs)
        s.blobs.set_capacity(o.max_blobs);
      else
        s.pixels.assign(bytes, 0);  // touched: no page faults later
    }
    if (keep) {  // enough buffers for the kept images of a full write-behind, and 2 more
      const std::uint32_t k = static_cast<std::uint32_t>(rt::next_power_of_two_at_least(
          o.slots_per_camera / std::min(o.keep_images_every, o.slots_per_camera) + 2));
      r->kept_[c].assign(k, std::vector<std::uint8_t>(bytes, 0));
      auto ring = rt::SpscRing<std::uint32_t>::create(k);
      if (!ring) return ring.error();
      r->kept_free_[c] = std::make_unique<rt::SpscRing<std::uint32_t>>(std::move(ring).value());
      for (std::uint32_t i = 0; i < k; ++i) (void)r->kept_free_[c]->try_push(i);
    }
    auto filled = rt::SpscRing<std::uint32_t>::create(o.slots_per_camera);
    auto free = rt::SpscRing<std::uint32_t>::create(o.slots_per_camera);
    if (!filled) return filled.error();
    if (!free) return free.error();
    r->filled_[c] = std::make_unique<rt::SpscRing<std::uint32_t>>(std::move(filled).value());
    r->free_[c] = std::make_unique<rt::SpscRing<std::uint32_t>>(std::move(free).value());
    for (std::uint32_t i = 0; i < o.slots_per_camera; ++i) (void)r->free_[c]->try_push(i);
  }
  r->units_.reserve(4 * static_cast<std::size_t>(o.slots_per_camera));
  return r;
}

FrameRecorder::FrameRecorder(const RecorderOptions& options, RecordingFiles files)
    : options_(options), files_(std::move(files)) {}

FrameRecorder::~FrameRecorder() {
  if (writer_.joinable()) {
    stop_.store(true, std::memory_order_release);
    writer_.join();
  }
}

void FrameRecorder::attach(pipeline::PipelineOptions& pipeline_options) noexcept {
  pipeline_options.tap = this;
  if (options_.blobs) {
    pipeline_options.blob_tap = this;
    pipeline_options.every_frame = true;
  }
}

void FrameRecorder::start() {
  if (!writer_.joinable()) writer_ = std::thread([this] { writer_loop(); });
}

bool FrameRecorder::number_of(std::size_t c, std::uint64_t sequence, std::uint64_t base,
                              std::uint64_t& number, bool count) noexcept {
  if (sequence < base) {  // older than the first frame: cannot be numbered
    if (count) dropped_[c].add();
    return false;
  }
  number = sequence - base;
  return options_.max_frames == 0 || number < options_.max_frames;
}

bool FrameRecorder::take_slot(std::size_t c, std::uint32_t& index) noexcept {
  bool got = free_[c]->try_pop(index);
  if (!got && options_.wait_for_slot_ms > 0) {  // lockstep only: wait for the writer
    const std::int64_t deadline =
        hal::monotonic_ns() + static_cast<std::int64_t>(options_.wait_for_slot_ms) * 1'000'000;
    while (!got && !failed() && hal::monotonic_ns() < deadline) {
      hal::sleep_until_ns(hal::monotonic_ns() + 500'000);
      got = free_[c]->try_pop(index);
    }
  }
  if (!got) dropped_[c].add();  // the writer is behind: drop this frame, counted
  return got;
}

void FrameRecorder::on_frame(int camera, const hal::Frame& frame) noexcept {
  if (camera < 0 || camera >= camera_count()) return;  // not a camera of this recording
  const auto c = static_cast<std::size_t>(camera);
  if (!have_base_) {
    have_base_ = true;
    base_sequence_ = frame.sequence;
    // release: the detect threads get this frame through the capture's rings after this
    // store; their acquire load (on_blobs) sees the base.
    base_plus_one_.store(frame.sequence + 1, std::memory_order_release);
  }
  std::uint64_t number = 0;
  // (blobs: the detect thread, the counter's single writer, counts the drop)
  if (!number_of(c, frame.sequence, base_sequence_, number, !options_.blobs)) return;
  // relaxed: a progress figure; a single writer (this thread).
  if (number + 1 > seen_.load(std::memory_order_relaxed))
    seen_.store(number + 1, std::memory_order_relaxed);
  if (options_.blobs) return;  // the blob list comes through on_blobs
  std::uint32_t index = 0;
  if (!take_slot(c, index)) return;
  Slot& s = slots_[c][index];
  s.sequence = frame.sequence;
  s.frame = static_cast<std::int64_t>(number);
  s.timestamp_ns = frame.timestamp_ns;
  s.missing = frame.missing || frame.image.empty();
  s.view = ImageView{};
  if (!s.missing) {
    const ImageView& in = frame.image;
    const auto row_bytes =
        static_cast<std::size_t>(in.width) * static_cast<std::size_t>(bytes_per_pixel(in.format));
    if (row_bytes * static_cast<std::size_t>(in.height) > s.pixels.size()) {
      dropped_[c].add();  // larger than configured: cannot happen with a sane backend
      (void)free_[c]->try_push(index);
      return;
    }
    for (int y = 0; y < in.height; ++y)
      std::memcpy(s.pixels.data() + static_cast<std::size_t>(y) * row_bytes, in.row8(y), row_bytes);
    s.view = ImageView{s.pixels.data(), in.width, in.height, static_cast<int>(row_bytes),
                       in.format,       in.maxval};
  }
  (void)filled_[c]->try_push(index);  // never full: it has a place for every slot
}

void FrameRecorder::on_blobs(int camera, const hal::Frame& frame, bool present,
                             const detect::BlobList& blobs) noexcept {
  if (!options_.blobs || camera < 0 || camera >= camera_count()) return;
  const auto c = static_cast<std::size_t>(camera);
  // acquire: pairs with on_frame's release store (see there).
  const std::uint64_t base1 = base_plus_one_.load(std::memory_order_acquire);
  std::uint64_t number = 0;
  if (base1 == 0 || !number_of(c, frame.sequence, base1 - 1, number, true)) return;
  std::uint32_t index = 0;
  if (!take_slot(c, index)) return;
  Slot& s = slots_[c][index];
  s.sequence = frame.sequence;
  s.frame = static_cast<std::int64_t>(number);
  s.timestamp_ns = frame.timestamp_ns;
  s.missing = !present;
  s.blobs.clear();
  s.blobs.set_levels(blobs.levels());
  for (const detect::Blob& b : blobs) (void)s.blobs.push_back(b);  // same capacity
  s.kept = -1;
  s.view = ImageView{};
  const ImageView& in = frame.image;
  std::uint32_t k = 0;
  if (present && kept_free_[c] && number % options_.keep_images_every == 0) {
    const auto row_bytes =
        static_cast<std::size_t>(in.width) * static_cast<std::size_t>(bytes_per_pixel(in.format));
    if (!kept_free_[c]->try_pop(k)) {
      kept_skipped_[c].add();
    } else if (row_bytes * static_cast<std::size_t>(in.height) > kept_[c][k].size()) {
      kept_skipped_[c].add();
      (void)kept_free_[c]->try_push(k);
    } else {
      std::uint8_t* px = kept_[c][k].data();
      for (int y = 0; y < in.height; ++y)
        std::memcpy(px + static_cast<std::size_t>(y) * row_bytes, in.row8(y), row_bytes);
      s.view =
          ImageView{px, in.width, in.height, static_cast<int>(row_bytes), in.format, in.maxval};
      s.kept = static_cast<std::int32_t>(k);
    }
  }
  (void)filled_[c]->try_push(index);  // never full: it has a place for every slot
}

void FrameRecorder::free_slot(int camera, std::int32_t slot) noexcept {
  if (slot < 0) return;
  const auto c = static_cast<std::size_t>(camera);
  Slot& s = slots_[c][static_cast<std::size_t>(slot)];
  if (s.kept >= 0) (void)kept_free_[c]->try_push(static_cast<std::uint32_t>(s.kept));
  s.kept = -1;
  (void)free_[c]->try_push(static_cast<std::uint32_t>(slot));
}

bool FrameRecorder::drain(bool flush) {
  bool got = false;
  auto on_drop = [this](int camera, const hal::PairEntry& e) {
    Unit u;
    u.frame = slots_[static_cast<std::size_t>(camera)][e.handle].frame;
    u.slot[camera] = static_cast<std::int32_t>(e.handle);
    units_.push_back(u);
  };
  const int n = camera_count();
  hal::FramePair pair;
  auto take = [&] {  // a silent camera's entry (kAbsentHandle): no slot
    Unit u;
    for (int k = 0; k < n; ++k) {
      const std::uint32_t h = pair.cam[k].handle;
      u.slot[k] = h == hal::kAbsentHandle ? -1 : static_cast<std::int32_t>(h);
      if (u.slot[k] >= 0) u.frame = slots_[static_cast<std::size_t>(k)][h].frame;
    }
    units_.push_back(u);
  };
  const std::int64_t now = hal::monotonic_ns();
  for (int c = 0; c < n; ++c) {
    std::uint32_t index = 0;
    while (filled_[static_cast<std::size_t>(c)]->try_pop(index)) {
      got = true;
      const Slot& s = slots_[static_cast<std::size_t>(c)][index];
      const std::int64_t key = options_.pair_by == pipeline::PairBy::kSequence
                                   ? static_cast<std::int64_t>(s.sequence)
                                   : s.timestamp_ns;
      if (pairer_->push(c, hal::PairEntry{key, index}, pair, on_drop, now)) take();
    }
  }
  while (pairer_->expire(now, pair)) take();  // sets that waited out a silent camera
  if (flush) pairer_->flush(on_drop);         // the frames whose partner never came
  return got;
}

void FrameRecorder::writer_loop() {
  for (;;) {
    // acquire: pairs with finish()'s release after the capture thread was joined, so the
    // drain below sees every frame the tap pushed.
    const bool stopping = stop_.load(std::memory_order_acquire);
    const bool got = drain(stopping);
    write_units();
    if (stopping) break;
    if (!got) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

Expected<void> FrameRecorder::finish() {
  if (writer_.joinable()) {
    stop_.store(true, std::memory_order_release);
    writer_.join();
  } else {
    drain(true);
    write_units();
  }
  auto synced = files_.finish();
  for (BlobFileWriter& w : blob_files_) {
    auto closed = w.close();
    if (synced && !closed) synced = closed;
  }
  if (error_) return *error_;
  return synced;
}

RecorderCounts FrameRecorder::counts() const noexcept {
  RecorderCounts k;
  k.frames_written = frames_written_.get();
  k.images_written = images_written_.get();
  k.bytes_written = bytes_written_.get();
  for (int c = 0; c < camera_count(); ++c)
    k.dropped.push_back(dropped_[static_cast<std::size_t>(c)].get());
  k.not_written = not_written_.get();
  for (int c = 0; c < camera_count(); ++c)
    k.without_image.push_back(without_image_[static_cast<std::size_t>(c)].get());
  k.blob_lists_written = blob_lists_written_.get();
  for (int c = 0; c < camera_count(); ++c)
    k.kept_skipped += kept_skipped_[static_cast<std::size_t>(c)].get();
  return k;
}

}  // namespace mocap::record
