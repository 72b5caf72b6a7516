// Security posture of the tracker (issue 8): `mocap run` opens no listening socket and
// no socket that accepts datagrams from anyone (the client library listens; the tracker
// only sends). The running process's sockets are looked up through /proc/<pid>/fd and
// matched by inode against /proc/<pid>/net/{tcp,tcp6,udp,udp6}: no TCP socket may be in
// LISTEN state and every UDP socket must be connected to its one destination (a remote
// address set, so the kernel drops datagrams from any other sender).
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "client/datagram.h"
#include "tests/reliability/damaged_fixture.h"

extern char** environ;

namespace mocap {
namespace {

std::set<std::string> socket_inodes(pid_t pid) {
  std::set<std::string> inodes;
  std::error_code ec;
  for (const auto& e :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
    const std::string target = std::filesystem::read_symlink(e.path(), ec).string();
    if (!ec && target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
  }
  return inodes;
}

struct InetSocket {
  std::string table, local, remote, state;
};

// The process's AF_INET/AF_INET6 sockets (Unix-domain sockets, e.g. iceoryx's, are local
// IPC protected by file permissions and are not listed).
std::vector<InetSocket> inet_sockets(pid_t pid) {
  const std::set<std::string> mine = socket_inodes(pid);
  std::vector<InetSocket> out;
  for (const char* table : {"tcp", "tcp6", "udp", "udp6"}) {
    std::ifstream f("/proc/" + std::to_string(pid) + "/net/" + table);
    std::string line;
    std::getline(f, line);  // header
    while (std::getline(f, line)) {
      std::istringstream ls(line);
      std::string sl, local, remote, state, queues, timer, retr, uid, timeout, inode;
      ls >> sl >> local >> remote >> state >> queues >> timer >> retr >> uid >> timeout >> inode;
      if (mine.count(inode) != 0) out.push_back({table, local, remote, state});
    }
  }
  return out;
}

bool remote_unset(const std::string& remote) {  // "00000000:0000" or the IPv6 form
  return remote.find_first_not_of("0:") == std::string::npos;
}

TEST(Security, RunOpensNoListeningOrOpenReceiveSocket) {
  test::TempDir tmp("security");
  const std::string bin = test::mocap_binary();
  std::vector<std::string> args = {
      bin, "run",           "--duration",   "5",     "--loop-frames",
      "4", "--no-realtime", "--no-iceoryx", "--udp", "127.0.0.1:47991"};
  std::vector<char*> argv;
  for (std::string& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  const std::string log = tmp.file("run.log");
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, bin.c_str(), &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);

  // Wait (bounded) until the tracker is publishing: its UDP socket exists and has sent.
  std::vector<InetSocket> socks;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(4);
  while (std::chrono::steady_clock::now() < until) {
    socks = inet_sockets(pid);
    bool sending = false;
    for (const auto& s : socks)
      if (s.table.rfind("udp", 0) == 0 && s.local.substr(s.local.find(':')) != ":0000")
        sending = true;
    if (sending) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_FALSE(socks.empty()) << "no UDP socket seen; output:\n" << test::read_file(log);
  for (const auto& s : socks) {
    SCOPED_TRACE(s.table + " " + s.local + " -> " + s.remote + " state " + s.state);
    if (s.table.rfind("tcp", 0) == 0) {
      EXPECT_NE(s.state, "0A") << "a listening TCP socket";
    } else {
      EXPECT_FALSE(remote_unset(s.remote))
          << "an unconnected UDP socket receives datagrams from anyone";
    }
  }
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << test::read_file(log);
}

// The receiver's validation (magic, version, length, CRC) catches every single-bit error
// anywhere in a datagram, header, records or CRC alike, and never writes the output.
// (Corrupted datagrams over a real socket are in tests/client/test_udp_receiver.cpp.)
TEST(Security, EveryBitFlipOfADatagramIsRejected) {
  client::JointsMessage msg;
  msg.sequence = 1234;
  msg.capture_ns = 5'000'000'000;
  msg.publish_ns = 5'001'000'000;
  msg.flags = client::kFlagAllBodiesFound;
  msg.joint_count = 2;
  msg.joints[0] = {0, 0, 1, {0.1f, 0.2f, 0.3f}, {1.0f, 0.0f, 0.0f, 0.0f}};
  msg.joints[1] = {1, 1, 1, {0.5f, 0.0f, 0.0f}, {0.9f, 0.1f, 0.2f, 0.3f}};
  std::uint8_t good[client::kMaxDatagramBytes];
  const std::size_t n = client::encode_datagram(msg, good, sizeof good);
  ASSERT_EQ(n, client::datagram_size(2));
  client::JointsMessage out;
  ASSERT_EQ(client::decode_datagram(good, n, out), client::DecodeStatus::kOk);
  out.sequence = 77;  // a marker: a rejected datagram must leave it alone
  int rejected = 0;
  for (std::size_t byte = 0; byte < n; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::uint8_t bad[client::kMaxDatagramBytes];
      std::copy(good, good + n, bad);
      bad[byte] = static_cast<std::uint8_t>(bad[byte] ^ (1u << bit));
      const client::DecodeStatus st = client::decode_datagram(bad, n, out);
      EXPECT_NE(st, client::DecodeStatus::kOk) << "byte " << byte << " bit " << bit;
      rejected += st != client::DecodeStatus::kOk ? 1 : 0;
    }
  }
  EXPECT_EQ(rejected, static_cast<int>(8 * n));
  EXPECT_EQ(out.sequence, 77u);
  // Truncated or extended by one byte: rejected on length.
  EXPECT_NE(client::decode_datagram(good, n - 1, out), client::DecodeStatus::kOk);
  EXPECT_EQ(client::decode_datagram(good, n + 1, out), client::DecodeStatus::kBadLength);
}

}  // namespace
}  // namespace mocap
