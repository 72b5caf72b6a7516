// Design: the out-of-tree consumer of the installed mocap client library: encodes a
// JointsMessage into a UDP datagram v1, sends it over loopback to a UdpReceiver of the
// library and checks what arrives. Exit 0 and "consumer ok" when everything matches.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>

#include "client/datagram.h"
#include "client/joints_message.h"
#include "client/udp_receiver.h"

int main() {
  using namespace mocap::client;
  auto rx = UdpReceiver::create("127.0.0.1:0");
  if (!rx) {
    std::fprintf(stderr, "consumer: %s\n", rx.error().message.c_str());
    return 1;
  }
  JointsMessage m;
  m.sequence = 42;
  m.capture_ns = 1000;
  m.joint_count = 1;
  m.joints[0].type = static_cast<std::uint8_t>(JointKind::kHinge);
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 0.25f;
  std::uint8_t buf[kMaxDatagramBytes];
  const std::size_t len = encode_datagram(m, buf, sizeof buf);
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(rx->port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::sendto(fd, buf, len, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  ::close(fd);
  for (int i = 0; i < 50 && !rx->has_message(); ++i) rx->wait(std::chrono::milliseconds(100));
  if (!rx->has_message() || rx->latest().sequence != 42 || rx->latest().joints[0].a[0] != 0.25f) {
    std::fprintf(stderr, "consumer: the datagram did not arrive intact\n");
    return 1;
  }
  std::printf("consumer ok\n");
  return 0;
}
