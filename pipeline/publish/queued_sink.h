// Design: the base of every slow output (DDS, JSON over WebSocket, files): publish() on
// the real-time publish thread only copies the frame result into a bounded drop-oldest
// queue (rt::DropOldestQueue, `depth` waiting frames) and returns; a worker thread of
// its own (non-real-time, started at setup) takes the frames oldest first and calls the
// derived class's encode(), which may allocate, lock, log and block. When the worker
// falls behind, the oldest waiting frame is dropped and counted (`dropped`), so a
// stalled transport never stalls the tracker and the newest data always gets in.
// Exceptions from encode()/idle() are caught on the worker and counted as failures.
//
// Wake-up: the publish thread makes NO syscall: publish() is the queue's copy only. The
// worker polls the queue: every 1 ms while frames arrive, every 20 ms after 1 s without
// one (an idle tracker costs 50 wake-ups/s per output), and calls idle() (accept
// connections, re-announce, ...) about every 100 ms. Its Doorbell is rung by stop()
// only. Measured (docs/performance.md, 2026-12-02): ringing a futex from the SCHED_FIFO
// publish thread to wake this worker cost up to 2.9 ms per frame on the 2-vCPU VM with
// the Foxglove viewer connected (sink p99 0.6-1.7 ms); polling costs the output frames
// at most 1 ms of extra latency (0.5 ms on average) and ~1000 wake-ups/s per active
// slow output on the worker's side, not on the real-time threads.
//
// Lifetime: derived classes MUST call stop() in their own destructor (the base
// destructor also calls it, but by then the derived part is gone while the worker might
// still be inside encode()). start() and stop() are setup/teardown calls of the owner.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "core/expected.h"
#include "pipeline/publish/output_sink.h"
#include "rt/counter.h"
#include "rt/doorbell.h"
#include "rt/drop_oldest_queue.h"

namespace mocap::publish {

class QueuedSink : public OutputSink {
 public:
  // Preallocates `depth` waiting FrameResult slots (plus the producer's and the worker's
  // working copies); depth is clamped to [1, 1024].
  explicit QueuedSink(int depth);
  ~QueuedSink() override;

  // Starts the worker thread (setup). Error: the thread could not be created.
  Expected<void> start();
  // Wakes and joins the worker (frames still waiting are not encoded). Idempotent.
  void stop() noexcept;

  // Publish thread: copy in; when `depth` frames are waiting, drop the oldest (counted).
  // Always true: the frame was accepted (a drop is not a failure of this frame).
  bool publish(const FrameResult& frame) noexcept final;
  OutputCounters counters() const noexcept override;

  // Frames waiting (a hint, any thread).
  std::size_t queued_approx() const noexcept { return queue_->size_approx(); }

 protected:
  // Worker thread: encode and send one frame; may allocate; an exception is a failure.
  virtual void encode(const FrameResult& frame) = 0;
  // Worker thread: called about every 100 ms while no frame is waiting.
  virtual void idle() {}

 private:
  void worker_loop() noexcept;

  std::unique_ptr<rt::DropOldestQueue<FrameResult>> queue_;
  rt::Doorbell bell_;
  std::atomic<bool> stop_{false};
  std::thread worker_;
  rt::Counter published_;  // worker: encode() returned
  rt::Counter failures_;   // worker: encode() threw
};

}  // namespace mocap::publish
