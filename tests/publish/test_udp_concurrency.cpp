// Design: the deployment shape on one machine: the tracker thread publishes a stream of
// frames over 127.0.0.1 while a motor-controller thread runs a ~1 kHz wait()/latest()
// loop. Whatever the scheduler does, every frame is either accepted or counted as
// dropped (accepted + dropped_frames == N), nothing valid is rejected, and the newest
// frame arrives. The first and last frames are re-sent until seen (counted as stale),
// so the accounting starts at 1 and ends at N. Bounded: 20 s deadline. Run under TSan.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "client/udp_receiver.h"
#include "pipeline/publish/udp_publisher.h"

namespace {

using mocap::client::JointsMessage;

TEST(UdpConcurrency, PublisherThreadToControllerLoopAccountsForEveryFrame) {
  auto rx = mocap::client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(rx.ok());
  auto pub = mocap::publish::UdpPublisher::create({"127.0.0.1:" + std::to_string(rx->port())});
  ASSERT_TRUE(pub.ok());

  constexpr std::uint64_t kFrames = 3000;
  // memory_order: seen_seq is a plain progress signal from the receiver thread (release)
  // to the publisher (acquire); stop ends the receiver loop; no other data is shared
  // until join(), which orders the final reads of the receiver's counters.
  std::atomic<std::uint64_t> seen_seq{0};
  std::atomic<bool> stop{false};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);

  std::thread controller([&] {
    auto& r = rx.value();
    while (!stop.load(std::memory_order_acquire) && std::chrono::steady_clock::now() < deadline) {
      r.wait(std::chrono::microseconds(1000));
      if (r.has_message()) seen_seq.store(r.latest().sequence, std::memory_order_release);
    }
  });

  JointsMessage m;
  m.joint_count = 8;
  auto send_until_seen = [&](std::uint64_t seq) {
    m.sequence = seq;
    m.capture_ns = static_cast<std::int64_t>(seq);
    for (int i = 0; i < 2000 && seen_seq.load(std::memory_order_acquire) < seq; ++i) {
      pub->publish(m);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  };
  send_until_seen(1);
  for (std::uint64_t seq = 2; seq < kFrames; ++seq) {
    m.sequence = seq;
    m.capture_ns = static_cast<std::int64_t>(seq);
    m.joints[0].a[0] = static_cast<float>(seq);
    pub->publish(m);
    if (seq % 64 == 0) std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  send_until_seen(kFrames);
  stop.store(true, std::memory_order_release);
  controller.join();

  const auto& c = rx->counters();
  ASSERT_EQ(rx->latest().sequence, kFrames);
  EXPECT_EQ(c.accepted + c.dropped_frames, kFrames);
  EXPECT_EQ(c.rejected_total(), 0u);
  EXPECT_EQ(c.datagrams, c.accepted + c.stale);
  EXPECT_EQ(pub->counters().other_errors, 0u);
}

}  // namespace
