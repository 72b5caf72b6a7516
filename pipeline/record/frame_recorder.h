// Design: `mocap record`'s tap on the live pipeline (pipeline::FrameTap) and its writer.
//
//   capture thread --on_frame--> [slot pool per camera (2..kMaxCameras): images copied into
//   (hot path)                    preallocated slots; indices through two SPSC rings]
//                                        |
//                     writer thread <----+  pairs the frames with hal::FramePairer (the
//                     (not real-time)       pipeline's pairing: by trigger sequence or by
//                                           timestamp), writes each frame's PGMs, then its
//                                           frames.csv row (RecordingFiles), frees slots
//
// on_frame (capture thread) is noexcept and allocation-free: it takes a free slot, copies
// the image (a memcpy of one frame) and pushes the slot index; with no free slot the frame
// is dropped and counted (drops[camera]) -- capture never blocks. Only in lockstep pacing
// (wait_for_slot_ms > 0) it waits for a slot, as the lockstep trigger waits for the
// pipeline, so that a replay is recorded image for image.
// Frame numbers: the frame's sequence number minus that of the first frame written (so a
// replay keeps its source's numbers; a trigger the pipeline skipped is a gap). A frame
// is one row of frames.csv with the timestamp of the first camera's image that it has; a
// camera without an image for it (dropped, missing in a replay) has no file (the
// matcher's partial frames are merged into one unit per frame before writing). After the first
// write error the writer writes nothing more (the error is kept and failed() turns true); what was
// written stays a valid recording (RecordingFiles).
// Blob recordings (`mocap record --blobs`, options.blobs): the recorder is also the
// pipeline's BlobTap. on_frame (capture thread) then only numbers the frames; on_blobs
// (each camera's detect thread, the producer of that camera's rings) copies the frame's
// blob list into the slot (and, every keep_images_every-th frame, the image into a small
// pool of its own), with the same drops and lockstep wait as on_frame; the writer
// appends one chunk per camera and frame to blobs/<camera>.blobs (formats/blob_file.h),
// writes the kept images as PGM, then the frames.csv row.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/expected.h"
#include "formats/blob_file.h"
#include "hal/frame_pairer.h"
#include "pipeline/pipeline.h"
#include "pipeline/record/recording_files.h"
#include "rt/counter.h"
#include "rt/spsc_ring.h"

namespace mocap::record {

struct CameraGeometry {
  int width = 0, height = 0;
  PixelFormat format = PixelFormat::kMono8;
};

struct RecorderOptions {
  std::string dir;                        // exists, holds no frames.csv yet
  std::vector<std::string> camera_names;  // one per camera of the rig (2..kMaxCameras)
  std::vector<CameraGeometry> cameras;    // the configured image sizes (slot sizes), same order
  std::uint32_t slots_per_camera = 64;    // power of two >= 2: the write-behind buffer
  std::uint64_t max_frames = 0;           // frames numbered >= this are ignored (0: all)
  int wait_for_slot_ms = 0;               // > 0 only in lockstep pacing
  pipeline::PairBy pair_by = pipeline::PairBy::kSequence;
  std::int64_t pair_tolerance_ns = 1'000'000;
  // Per camera: how long (ns) the others' frames wait for it before it is silent and the
  // frames are written without it (hal::FramePairer; camera nodes the central does not
  // trigger: PipelineOptions::silent_after_ns). 0: always waited for.
  std::array<std::int64_t, kMaxCameras> silent_after_ns{};
  std::uint64_t byte_budget =
      0;               // test hook: ENOSPC past this many bytes (0: off; blobs: per file)
  bool blobs = false;  // blob lists (on_blobs) instead of images (on_frame)
  std::uint32_t max_blobs = 512;        // blobs: the detector's capacity per frame
  std::uint32_t keep_images_every = 0;  // blobs: also every Nth frame's images as PGM (0: none)
  std::int64_t sync_interval_ns =
      1'000'000'000;  // blobs: fdatasync of each file at most this often
};

struct RecorderCounts {
  std::uint64_t frames_written = 0;  // rows of frames.csv
  std::uint64_t images_written = 0;  // PGM files
  std::uint64_t bytes_written = 0;
  std::vector<std::uint64_t> dropped;  // per camera: images dropped at the tap (no free slot)
  std::uint64_t not_written = 0;       // frames queued when writing failed or out of order
  // per camera: frames written without its image (or blob list): dropped at the tap
  // (`dropped`), or never delivered by the camera (a missed trigger, a missing file)
  std::vector<std::uint64_t> without_image;
  std::uint64_t blob_lists_written = 0;  // blobs: chunks of the blob files
  std::uint64_t kept_skipped = 0;        // blobs: images to keep for which no buffer was free
};

class FrameRecorder final : public pipeline::FrameTap, public pipeline::BlobTap {
 public:
  // Allocates every slot and opens frames.csv (RecordingFiles::open).
  static Expected<std::unique_ptr<FrameRecorder>> create(const RecorderOptions& options);
  ~FrameRecorder() override;

  // Connects the recorder to the live pipeline's options as `mocap record` runs it: the
  // frame tap; in blob mode also the blob tap, with every_frame: every stage takes every
  // frame in order, so the detect stages hand the tap each frame and identify and publish
  // follow them without skipping (a stall delays frames and drops none while the rings
  // hold them).
  void attach(pipeline::PipelineOptions& pipeline_options) noexcept;
  // Starts the writer thread.
  void start();
  // Capture thread (hot path).
  void on_frame(int camera, const hal::Frame& frame) noexcept override;
  // A detect thread (hot path; blob recordings).
  void on_blobs(int camera, const hal::Frame& frame, bool present,
                const detect::BlobList& blobs) noexcept override;
  // Waits for the writer to write everything queued, stops it and syncs the folder. The
  // first write error, if any (one line naming the file and the problem).
  Expected<void> finish();

  // Any thread.
  RecorderCounts counts() const noexcept;
  bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }
  // Frames (by number) the tap has seen so far, and whether every one of max_frames did.
  std::uint64_t frames_seen() const noexcept { return seen_.load(std::memory_order_relaxed); }

 private:
  struct Slot {
    std::vector<std::uint8_t> pixels;  // tightly packed, the camera's size
    ImageView view;                    // into pixels (empty when missing)
    std::uint64_t sequence = 0;
    std::int64_t frame = 0;  // sequence - the first sequence seen
    std::int64_t timestamp_ns = 0;
    bool missing = false;
    detect::BlobList blobs{0};  // blobs: the frame's list (capacity max_blobs)
    std::int32_t kept = -1;     // blobs: index of the kept image's buffer, -1 none
  };
  struct Unit {  // one frame to write: slot index per camera, -1 if none
    Unit() noexcept { slot.fill(-1); }
    std::int64_t frame = 0;
    std::array<std::int32_t, kMaxCameras> slot;
  };

  explicit FrameRecorder(const RecorderOptions& options, RecordingFiles files);
  void writer_loop();
  // Pops the filled rings into the pairer; appends the completed frames to units_.
  bool drain(bool flush);
  void write_unit(const Unit& u);
  // Sorts units_ by frame, merges the units of one frame, writes them, clears units_.
  void write_units();
  void free_slot(int camera, std::int32_t slot) noexcept;
  // Takes a free slot of `camera` (lockstep: waits for one); false: dropped (counted).
  bool take_slot(std::size_t camera, std::uint32_t& index) noexcept;
  // The frame's number from its sequence (false: before the first frame or past max_frames).
  // `count`: a frame before the first is counted as dropped (by the counter's writer).
  bool number_of(std::size_t camera, std::uint64_t sequence, std::uint64_t base,
                 std::uint64_t& number, bool count) noexcept;
  Expected<void> write_blobs(int camera, std::int64_t number, const Slot& s);

  RecorderOptions options_;
  RecordingFiles files_;
  int camera_count() const noexcept { return static_cast<int>(options_.cameras.size()); }

  std::array<std::vector<Slot>, kMaxCameras> slots_;
  std::array<std::unique_ptr<rt::SpscRing<std::uint32_t>>, kMaxCameras> filled_, free_;
  // Blob recordings: one file per camera (writer thread) and the kept images' buffers.
  std::vector<BlobFileWriter> blob_files_;
  std::array<std::vector<std::vector<std::uint8_t>>, kMaxCameras> kept_;
  std::array<std::unique_ptr<rt::SpscRing<std::uint32_t>>, kMaxCameras> kept_free_;
  std::atomic<std::uint64_t> base_plus_one_{0};  // blobs: capture thread -> detect threads
  std::optional<hal::FramePairer> pairer_;       // writer thread
  std::vector<Unit> units_;                      // writer thread, reserved
  std::int64_t last_frame_ = -1;                 // writer thread: tap numbering
  std::int64_t first_frame_ = -1;                // writer thread: the tap's number of frame 0
  std::optional<Error> error_;                   // writer thread until joined

  // Capture thread.
  bool have_base_ = false;
  std::uint64_t base_sequence_ = 0;

  rt::Counter dropped_[kMaxCameras], frames_written_, images_written_, bytes_written_, not_written_;
  rt::Counter without_image_[kMaxCameras];
  rt::Counter blob_lists_written_, kept_skipped_[kMaxCameras];  // kept_skipped_: detect threads
  std::atomic<std::uint64_t> seen_{0};
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::thread writer_;
};

}  // namespace mocap::record
