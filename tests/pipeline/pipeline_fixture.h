// Shared set-up of the pipeline tests: one short pre-rendered sim loop (process-wide),
// the simulated cameras on it (2 by default, or a loop of 3..8 cameras), a FrameProcessor with the
// scene's true model, and a recording sink that stores messages in preallocated memory
// (allocation-free).
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include "hal/sim_camera.h"
#include "pipeline/pipeline.h"
#include "pipeline/publish/udp_publisher.h"

namespace mocap::pipeline::test {

// Loop length: rendering dominates a test process's run time (each ctest test is its own
// process), so binaries that need fewer distinct frames define a shorter loop.
#ifndef MOCAP_PIPELINE_TEST_LOOP_FRAMES
#define MOCAP_PIPELINE_TEST_LOOP_FRAMES 30
#endif

inline std::shared_ptr<const hal::SimFrameLoop> shared_loop() {
  static std::shared_ptr<const hal::SimFrameLoop> loop = [] {
    sim::SimOptions o;
    o.frames = MOCAP_PIPELINE_TEST_LOOP_FRAMES;
    auto l = hal::SimFrameLoop::render(o);
    EXPECT_TRUE(l.ok()) << (l.ok() ? "" : l.error().message);
    return l.ok() ? *l : nullptr;
  }();
  return loop;
}

// A loop of `frames` frames rendered for one test (a test that needs fewer frames than
// shared_loop() renders only these, in its own process).
inline std::shared_ptr<const hal::SimFrameLoop> render_loop(int frames, int cameras = 2) {
  sim::SimOptions o;
  o.frames = frames;
  o.cameras = cameras;  // 3..8: the built-in arc around the robot
  auto l = hal::SimFrameLoop::render(o);
  EXPECT_TRUE(l.ok()) << (l.ok() ? "" : l.error().message);
  return l.ok() ? *l : nullptr;
}

struct SimRigFixture {
  std::shared_ptr<const hal::SimFrameLoop> loop;
  std::shared_ptr<hal::SimTrigger> trigger;
  std::vector<std::unique_ptr<hal::SimCamera>> cams;  // every camera of the loop

  // `frames`: the loop to serve (default: shared_loop()).
  explicit SimRigFixture(int buffers = 6, std::shared_ptr<const hal::SimFrameLoop> frames = {})
      : loop(frames ? std::move(frames) : shared_loop()) {
    trigger = std::make_shared<hal::SimTrigger>(loop);
    for (int c = 0; c < loop->cameras(); ++c) {
      auto cam = hal::SimCamera::open(trigger, c);
      EXPECT_TRUE(cam.ok());
      cams.push_back(std::move(cam).value());
      hal::CameraConfig cfg = cams.back()->native_config();
      cfg.buffer_count = buffers;
      EXPECT_TRUE(cams.back()->configure(cfg).ok());
    }
  }
  std::vector<hal::Camera*> cameras() {
    std::vector<hal::Camera*> v;
    for (auto& c : cams) v.push_back(c.get());
    return v;
  }
  FrameProcessor processor() const {
    const sim::SimScene& sc = loop->scene();
    // The pipeline tests check the plumbing (every frame, in order, true angles), so they
    // also take poses that rest on partly occluded markers (coverage over accuracy).
    TrackerConfig config;
    config.identify.min_whole_markers = 0;
    auto p = FrameProcessor::create(sc.rig, sc.targets, &sc.joints_true, config);
    EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message);
    return std::move(p).value();
  }
};

// Stores up to `capacity` messages; optional sleep per publish (a slow transport), on
// every message or, with sleep_every = N, on every Nth (a transport that stalls now and
// then).
class RecordingSink final : public publish::OutputSink {
 public:
  explicit RecordingSink(std::size_t capacity, int sleep_us = 0, int sleep_every = 1)
      : messages_(capacity), sleep_us_(sleep_us), sleep_every_(sleep_every) {}
  const char* name() const noexcept override { return "recording"; }
  publish::OutputCounters counters() const noexcept override { return {}; }
  bool publish(const publish::FrameResult& frame) noexcept override {
    const client::JointsMessage& m = frame.joints;
    const std::size_t n = count_.load(std::memory_order_relaxed);  // single writer
    if (sleep_us_ > 0 && n % static_cast<std::size_t>(sleep_every_) == 0)
      std::this_thread::sleep_for(std::chrono::microseconds(sleep_us_));
    if (n >= messages_.size()) return false;
    messages_[n] = m;
    ResultSummary& r = results_[n];
    r.body_count = frame.body_count;
    r.marker_count = frame.marker_count;
    r.point_count = frame.point_count;
    r.bodies_found = 0;
    for (int b = 0; b < frame.body_count; ++b) r.bodies_found += frame.bodies[b].found;
    r.body0_found = frame.body_count > 0 && frame.bodies[0].found != 0;
    r.t0_mm = frame.bodies[0].t_world_body_mm;
    count_.store(n + 1, std::memory_order_release);  // publishes messages_[n]
    return true;
  }
  std::size_t count() const noexcept { return count_.load(std::memory_order_acquire); }
  const client::JointsMessage& operator[](std::size_t i) const { return messages_[i]; }
  // What the rest of the FrameResult carried (bodies, labelled markers, points).
  struct ResultSummary {
    int body_count = 0, bodies_found = 0, marker_count = 0, point_count = 0;
    bool body0_found = false;
    std::array<double, 3> t0_mm{};
  };
  const ResultSummary& result(std::size_t i) const { return results_[i]; }

 private:
  std::vector<client::JointsMessage> messages_;
  std::vector<ResultSummary> results_ = std::vector<ResultSummary>(messages_.size());
  std::atomic<std::size_t> count_{0};
  int sleep_us_ = 0;
  int sleep_every_ = 1;
};

inline PipelineOptions test_options() {
  PipelineOptions o;
  o.realtime = false;  // be polite on a shared test machine (no SCHED_FIFO, no pinning)
  o.lock_memory = false;
  return o;
}

// Waits (bounded) until the pipeline has handled every triggered frame.
inline void wait_finished(const Pipeline& p, double max_seconds = 30.0) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_seconds);
  while (!p.finished() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

inline std::uint64_t counter(const PipelineStats& s, const std::string& name) {
  for (const auto& [n, v] : s.counters)
    if (n == name) return v;
  ADD_FAILURE() << "no counter " << name;
  return 0;
}

// A sink that sends each frame's joints through a UdpPublisher, with the publisher's
// counters in reach of the test.
class UdpPublisherSink final : public publish::OutputSink {
 public:
  explicit UdpPublisherSink(publish::UdpPublisher p) : p_(std::move(p)) {}
  const char* name() const noexcept override { return "udp"; }
  publish::OutputCounters counters() const noexcept override { return {}; }
  bool publish(const publish::FrameResult& f) noexcept override {
    return p_.publish(f.joints) != publish::UdpPublisher::Status::kFailed;
  }
  const publish::UdpPublisher& publisher() const { return p_; }

 private:
  publish::UdpPublisher p_;
};

}  // namespace mocap::pipeline::test
