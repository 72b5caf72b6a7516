// Design: UdpReceiver on 127.0.0.1 with an ephemeral port, fed by a raw socket: valid
// messages, sequence gaps, stale/duplicate and restarted sequences, every kind of bad
// datagram (counted by reason, never accepted), a hostile random flood, setup errors,
// and zero allocations in steady-state receiving. Single-threaded: the kernel queues.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <random>
#include <vector>

#include "client/udp_receiver.h"
#include "tests/support/alloc_counter.h"

namespace {

using namespace mocap::client;

class Sender {
 public:
  explicit Sender(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    addr_.sin_family = AF_INET;
    addr_.sin_port = htons(port);
    addr_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Sender() { ::close(fd_); }
  void send(const std::uint8_t* p, std::size_t n) {
    ASSERT_EQ(::sendto(fd_, p, n, 0, reinterpret_cast<const sockaddr*>(&addr_), sizeof(addr_)),
              static_cast<ssize_t>(n));
  }
  void send_message(const JointsMessage& m) {
    std::uint8_t buf[kMaxDatagramBytes];
    const std::size_t n = encode_datagram(m, buf, sizeof(buf));
    ASSERT_GT(n, 0u);
    send(buf, n);
  }

 private:
  int fd_;
  sockaddr_in addr_{};
};

JointsMessage msg(std::uint64_t seq, std::int64_t capture_ns = -1) {
  JointsMessage m;
  m.sequence = seq;
  m.capture_ns = capture_ns < 0 ? static_cast<std::int64_t>(seq) * 1000 : capture_ns;
  m.joint_count = 2;
  m.joints[1].index = 1;
  m.joints[1].type = 1;
  m.joints[1].valid = 1;
  m.joints[1].a[0] = 0.25f * static_cast<float>(seq % 8);
  return m;
}

UdpReceiver make_receiver() {
  auto r = UdpReceiver::create("127.0.0.1:0");
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return std::move(r.value());
}

TEST(UdpReceiver, AcceptsValidMessagesAndCountsSequenceGaps) {
  UdpReceiver rx = make_receiver();
  ASSERT_NE(rx.port(), 0);
  EXPECT_FALSE(rx.has_message());
  Sender tx(rx.port());
  for (std::uint64_t seq : {10u, 11u, 12u, 15u, 16u, 20u}) tx.send_message(msg(seq));
  int accepted = 0;
  for (int i = 0; i < 200 && accepted < 6; ++i) accepted += rx.wait(std::chrono::milliseconds(10));
  EXPECT_EQ(accepted, 6);
  ASSERT_TRUE(rx.has_message());
  EXPECT_EQ(rx.latest().sequence, 20u);
  EXPECT_FLOAT_EQ(rx.latest().joints[1].a[0], 0.25f * 4.0f);
  EXPECT_EQ(rx.counters().dropped_frames, 2u + 3u);
  EXPECT_EQ(rx.counters().rejected_total(), 0u);
}

TEST(UdpReceiver, StaleAndDuplicateDroppedRestartAccepted) {
  UdpReceiver rx = make_receiver();
  Sender tx(rx.port());
  tx.send_message(msg(100));
  tx.send_message(msg(100));            // duplicate
  tx.send_message(msg(99));             // reordered
  tx.send_message(msg(0, 10'000'000));  // restart: sequence back, capture time later
  for (int i = 0; i < 200 && rx.counters().datagrams < 4; ++i)
    rx.wait(std::chrono::milliseconds(10));
  EXPECT_EQ(rx.counters().accepted, 2u);
  EXPECT_EQ(rx.counters().stale, 2u);
  EXPECT_EQ(rx.counters().restarts, 1u);
  EXPECT_EQ(rx.latest().sequence, 0u);
}

TEST(UdpReceiver, BadDatagramsAreCountedByReasonAndNeverUsed) {
  UdpReceiver rx = make_receiver();
  Sender tx(rx.port());
  std::uint8_t good[kMaxDatagramBytes];
  const std::size_t n = encode_datagram(msg(5), good, sizeof(good));
  std::vector<std::uint8_t> b(good, good + n);

  tx.send(b.data(), 10);  // too short
  auto bad = b;
  bad[1] = 'X';
  tx.send(bad.data(), bad.size());  // magic
  bad = b;
  bad[4] = 9;
  tx.send(bad.data(), bad.size());  // version
  tx.send(b.data(), b.size() - 1);  // length
  bad = b;
  bad[50] ^= 1;
  tx.send(bad.data(), bad.size());  // crc
  std::vector<std::uint8_t> huge(kMaxDatagramBytes + 500, 0xAB);
  tx.send(huge.data(), huge.size());  // oversized
  for (int i = 0; i < 200 && rx.counters().datagrams < 6; ++i)
    rx.wait(std::chrono::milliseconds(10));
  const auto& c = rx.counters();
  EXPECT_EQ(c.datagrams, 6u);
  EXPECT_EQ(c.accepted, 0u);
  EXPECT_FALSE(rx.has_message());
  EXPECT_EQ(c.rejected_for(DecodeStatus::kTooShort), 1u);
  EXPECT_EQ(c.rejected_for(DecodeStatus::kBadMagic), 1u);
  EXPECT_EQ(c.rejected_for(DecodeStatus::kBadVersion), 1u);
  EXPECT_EQ(c.rejected_for(DecodeStatus::kBadLength), 2u);
  EXPECT_EQ(c.rejected_for(DecodeStatus::kBadCrc), 1u);
  EXPECT_EQ(c.oversized, 1u);
  EXPECT_EQ(c.rejected_total(), 6u);
}

TEST(UdpReceiver, HostileRandomDatagramsAreAllRejected) {
  UdpReceiver rx = make_receiver();
  Sender tx(rx.port());
  std::mt19937 rng(42);
  std::vector<std::uint8_t> b(kMaxDatagramBytes + 8);
  const int kTotal = 2000;
  std::uint64_t sent = 0;
  // Batches of 25 datagrams (up to 2.3 KB each) fit the default receive buffer.
  for (int batch = 0; batch < kTotal / 25; ++batch) {
    for (int i = 0; i < 25; ++i) {
      const std::size_t n = rng() % b.size();
      for (std::size_t k = 0; k < n; ++k) b[k] = static_cast<std::uint8_t>(rng());
      if (i % 2 == 0 && n >= 6) {
        b[0] = 'M';
        b[1] = 'C';
        b[2] = 'A';
        b[3] = 'P';
        b[4] = 1;
        b[5] = 0;
      }
      tx.send(b.data(), n);
      ++sent;
    }
    for (int i = 0; i < 200 && rx.counters().datagrams < sent; ++i)
      rx.wait(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(rx.counters().datagrams, sent);
  EXPECT_EQ(rx.counters().accepted, 0u);
  EXPECT_EQ(rx.counters().rejected_total(), sent);
  tx.send_message(msg(1));  // still works afterwards
  for (int i = 0; i < 200 && !rx.has_message(); ++i) rx.wait(std::chrono::milliseconds(5));
  EXPECT_TRUE(rx.has_message());
}

TEST(UdpReceiver, SteadyStateReceivingAllocatesNothing) {
  UdpReceiver rx = make_receiver();
  Sender tx(rx.port());
  for (std::uint64_t s = 1; s <= 50; ++s) tx.send_message(msg(s));
  mocap::test::AllocationScope scope;
  int accepted = 0;
  for (int i = 0; i < 200 && accepted < 50; ++i) accepted += rx.wait(std::chrono::milliseconds(5));
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(accepted, 50);
  EXPECT_EQ(rx.poll(), 0);  // nothing pending: returns at once
}

TEST(UdpReceiver, SetupErrorsAreOneLine) {
  auto r = UdpReceiver::create("127.0.0.1");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "udp receiver: '127.0.0.1': expected HOST:PORT");
  r = UdpReceiver::create("127.0.0.1:70000");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "udp receiver: '127.0.0.1:70000': port must be 0..65535");
  r = UdpReceiver::create("127.0.0.1:9x");
  ASSERT_FALSE(r.ok());
  r = UdpReceiver::create(":9000");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "udp receiver: ':9000': empty host");
  UdpReceiver first = make_receiver();
  r = UdpReceiver::create("127.0.0.1:" + std::to_string(first.port()));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("bind: Address already in use"), std::string::npos)
      << r.error().message;
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

}  // namespace
