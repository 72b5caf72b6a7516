// Design: the RouDi probe never blocks and tells a bound Unix datagram socket from a
// missing path and from a stale socket file (bound once, owner gone), and a RouDi of
// another primary group (which would make iceoryx's initRuntime hang, then abort).
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "client/roudi_probe.h"
#if MOCAP_CLIENT_HAVE_ICEORYX
#include "client/iceoryx_runtime.h"
#endif
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

TEST(RouDiProbe, GroupOfTheSocketMustBeThePrimaryGroup) {
  // iceoryx 2.0 clients whose primary group is not RouDi's hang in initRuntime and then
  // abort: the probe says so first.
  mocap::test::TempDir dir("roudi_probe_gid");
  const std::string path = dir.file("roudi");
  const int fd = bind_unix_dgram(path);
  ASSERT_GE(fd, 0);
  mocap::client::RouDiProbe p = mocap::client::probe_roudi(path.c_str());
  EXPECT_EQ(p.status, mocap::client::RouDiStatus::kRunning);
  EXPECT_EQ(p.roudi_gid, ::getegid());
  if (::geteuid() != 0) {
    ::close(fd);
    GTEST_SKIP() << "changing the socket's group needs root";
  }
  const gid_t other = ::getegid() + 4242;
  ASSERT_EQ(::chown(path.c_str(), static_cast<uid_t>(-1), other), 0);
  p = mocap::client::probe_roudi(path.c_str());
  EXPECT_EQ(p.status, mocap::client::RouDiStatus::kWrongGroup);
  EXPECT_EQ(p.roudi_gid, other);
  EXPECT_TRUE(mocap::client::roudi_running(path.c_str()));  // it runs, for this client in vain
#if MOCAP_CLIENT_HAVE_ICEORYX
  const auto rt = mocap::client::init_iceoryx_runtime("probe_test", path.c_str());
  ASSERT_FALSE(rt.ok());  // fails at once instead of hanging in initRuntime
  EXPECT_NE(rt.error().message.find("primary group"), std::string::npos) << rt.error().message;
#endif
  ::close(fd);
  EXPECT_EQ(mocap::client::probe_roudi(path.c_str()).status,
            mocap::client::RouDiStatus::kNotRunning);
}

}  // namespace
