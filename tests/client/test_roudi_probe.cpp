// Design: the RouDi probe never blocks and tells a bound Unix datagram socket from a
// missing path and from a stale socket file (bound once, owner gone).
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "client/roudi_probe.h"
#include "tests/support/test_support.h"

namespace {

int bind_unix_dgram(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

TEST(RouDiProbe, MissingStaleAndLiveSockets) {
  mocap::test::TempDir dir("roudi_probe");
  const std::string path = dir.file("roudi");
  EXPECT_FALSE(mocap::client::roudi_running(path.c_str()));
  const int fd = bind_unix_dgram(path);
  ASSERT_GE(fd, 0);
  EXPECT_TRUE(mocap::client::roudi_running(path.c_str()));
  ::close(fd);  // the file stays: a stale socket like a crashed RouDi leaves behind
  EXPECT_FALSE(mocap::client::roudi_running(path.c_str()));
  EXPECT_FALSE(mocap::client::roudi_running(nullptr));
  EXPECT_FALSE(mocap::client::roudi_running(""));
  EXPECT_FALSE(mocap::client::roudi_running(std::string(200, 'x').c_str()));
}

}  // namespace
