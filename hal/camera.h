// Design: the camera hardware abstraction layer. One interface for every backend
// (V4L2, libcamera, replay; the simulator's camera plugs in the same way):
//   configure  (setup, Expected)  : format GREY/Y16, size, exposure, gain, frame rate,
//                                   trigger mode; the backend reports what it achieved
//   start      (setup, Expected)  : allocate/map buffers and arm the capture
//   trigger    (hot, noexcept)    : software trigger, where the trigger mode is kSoftware
//   dequeue    (hot, noexcept)    : wait up to timeout_ms for the next frame; the Frame
//                                   is a zero-copy view into a backend-owned buffer
//   release    (hot, noexcept)    : give the buffer back (every dequeued frame, once)
//   stop       (setup)            : disarm and unmap
// State machine: kClosed -configure-> kConfigured -start-> kStreaming -stop->
// kConfigured; any fatal device failure (device unplugged, unrecoverable I/O) moves
// to kError, where hot calls return kDeviceLost and only stop()/destruction are valid.
// Hot-path calls return a CameraStatus and count failures in CameraCounters (single
// writer: the thread driving the camera; readable from any thread). A camera object is
// driven by ONE thread at a time (the capture thread; on a camera node, the detection
// worker that holds it, hand-overs ordered by release/acquire: pipeline/node/
// node_runner.h); other stages reach its buffers through rings and hand them back to that
// thread for release().
// Backends that own their state derive from CameraBase (hal/camera_base.h), which keeps
// name/state/config/notice/counters and the sequence-gap counting for them.
#pragma once

#include <cstdint>
#include <string>

#include "core/capture_modes.h"
#include "core/clock.h"
#include "core/expected.h"
#include "core/image.h"
#include "rt/counter.h"

namespace mocap::detect {
class BlobList;
}

namespace mocap::hal {

using mocap::TriggerMode;  // core/capture_modes.h

enum class CameraState : std::uint8_t { kClosed, kConfigured, kStreaming, kError };

enum class CameraStatus : std::uint8_t {
  kOk,
  kTimeout,        // no frame within timeout_ms (counted)
  kAgain,          // woken but no frame ready (EAGAIN/EINTR): call again, not an error
  kCorruptFrame,   // the driver flagged the frame bad or short; buffer requeued (counted)
  kNoBuffer,       // every buffer is held by the caller: release some first (counted)
  kEndOfStream,    // replay: no more frames
  kNotStreaming,   // called in the wrong state
  kUnsupported,    // e.g. trigger() when the trigger mode is not kSoftware
  kInvalidBuffer,  // release() of a frame this camera does not hold out (counted)
  kIoError,        // a failed system call; the stream goes on (counted)
  kDeviceLost,     // the device is gone (ENODEV) or unusable: state kError (counted)
};

const char* to_string(CameraStatus s) noexcept;
const char* to_string(CameraState s) noexcept;
const char* to_string(TriggerMode m) noexcept;

struct CameraConfig {
  PixelFormat format = PixelFormat::kMono8;  // kMono8 = GREY, kMono16 = Y16
  int width = 0;
  int height = 0;
  int exposure_us = 1000;      // <= 0: leave the device's setting
  double gain = -1.0;          // < 0: leave the device's setting. V4L2: the V4L2_CID_GAIN
                               // value (driver units); libcamera: AnalogueGain factor
  double frame_rate_hz = 0.0;  // free-run rate; <= 0: leave the device's setting
  TriggerMode trigger = TriggerMode::kFreeRun;
  int buffer_count = 4;  // driver/pool buffers (>= 2)
};

// One captured image. `image` points into a buffer owned by the camera until
// release(frame). Trivially copyable, so it can travel through an rt::SpscRing.
// Two times: `timestamp_ns` is the DATA's capture time (published as the message's
// capture_ns, used to pair cameras by timestamp and by identification's temporal prior);
// latency_origin_ns() is the LOCAL instant this process's latency statistics start at.
// For a live camera they are the same instant (the exposure/trigger on this host's
// CLOCK_MONOTONIC) and `delivered_ns` stays 0; a replay keeps the recording's timestamps
// as the data's and sets `delivered_ns` to the instant of the software trigger that
// released the frame (free-running: the instant it delivered the frame).
struct Frame {
  ImageView image;                 // empty when `missing`
  std::uint64_t sequence = 0;      // trigger/frame sequence number (per camera, from 0)
  std::int64_t timestamp_ns = 0;   // exposure/trigger time, CLOCK_MONOTONIC (replay: the
                                   // recording's timestamp)
  std::int64_t received_ns = 0;    // when dequeue returned it, CLOCK_MONOTONIC
  std::int64_t delivered_ns = 0;   // replay: its trigger (or delivery), CLOCK_MONOTONIC;
                                   // 0: timestamp_ns is local (live cameras)
  std::uint32_t buffer_index = 0;  // backend buffer; used by release()
  bool missing = false;            // replay: this camera has no image for this frame
  // A camera node's frame (pipeline/node/node_camera.h): the blobs its node detected,
  // owned by the camera until release(); no image. The detect stage passes them through.
  const detect::BlobList* blobs = nullptr;
};

// The local CLOCK_MONOTONIC instant a frame's latencies are measured from: the exposure/
// trigger time of a live camera, a replayed frame's trigger or delivery (see Frame).
inline std::int64_t latency_origin_ns(const Frame& f) noexcept {
  return f.delivered_ns != 0 ? f.delivered_ns : f.timestamp_ns;
}

struct CameraCounters {
  rt::Counter frames;     // frames returned by dequeue (kOk)
  rt::Counter timeouts;   // kTimeout
  rt::Counter errors;     // kIoError, kCorruptFrame, failed releases/triggers
  rt::Counter dropped;    // frames lost before us: gaps in the sequence numbers
  rt::Counter missing;    // replay: frames marked missing
  rt::Counter no_buffer;  // kNoBuffer
};

class Camera {
 public:
  virtual ~Camera() = default;
  Camera() = default;
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // Short identification for messages: the device path, libcamera id, "replay:cam0".
  virtual const std::string& name() const noexcept = 0;
  virtual CameraState state() const noexcept = 0;

  // kClosed/kConfigured -> kConfigured. Fails (one line naming the device and the
  // setting) when the device cannot do what is asked; the achieved configuration is
  // in config(). Settings the device lacks but that are not required (e.g. a trigger
  // control) fall back and are explained in notice().
  virtual Expected<void> configure(const CameraConfig& config) = 0;
  // kConfigured -> kStreaming: buffers allocated/mapped and queued, capture armed.
  virtual Expected<void> start() = 0;
  // kStreaming/kError -> kConfigured (kError stays kError). Frames not yet released
  // become invalid.
  virtual void stop() noexcept = 0;

  virtual CameraStatus trigger() noexcept = 0;
  // A camera whose software trigger travels before it fires (a camera node's, over the
  // network) is triggered ahead: the capture stage calls trigger_at(at_ns) up to
  // trigger_lead_ns() before the trigger instant at_ns (CLOCK_MONOTONIC), and the camera
  // fires at at_ns (at once when the trigger arrives later). 0: no lead, trigger() at
  // the instant. A frame's latency starts at at_ns either way.
  virtual std::int64_t trigger_lead_ns() const noexcept { return 0; }
  virtual CameraStatus trigger_at(std::int64_t at_ns) noexcept {
    (void)at_ns;
    return trigger();
  }
  // The camera's frames carry blobs detected elsewhere (Frame::blobs: a camera node's)
  // and no image: the pipeline hands them on without a detection thread.
  virtual bool delivers_blobs() const noexcept { return false; }
  virtual CameraStatus dequeue(Frame& out, int timeout_ms) noexcept = 0;
  virtual CameraStatus release(const Frame& frame) noexcept = 0;

  // The configuration achieved by configure() (what the device accepted).
  virtual const CameraConfig& config() const noexcept = 0;
  // One line on fallbacks taken at configure() (empty when none).
  virtual const std::string& notice() const noexcept = 0;
  virtual const CameraCounters& counters() const noexcept = 0;
};

// The clock of every timestamp in the HAL and the live output (core/clock.h).
using mocap::monotonic_ns;
using mocap::sleep_until_ns;

}  // namespace mocap::hal
