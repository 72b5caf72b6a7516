// Design: a non-blocking check that the iceoryx daemon RouDi runs, done BEFORE
// iox::runtime::PoshRuntime::initRuntime, which blocks forever without RouDi (iceoryx
// 2.0.3). RouDi listens on the Unix datagram socket /tmp/roudi; connect() on a datagram
// socket never blocks: it succeeds when a process has the address bound, and fails with
// ECONNREFUSED (stale file) or ENOENT (no file) otherwise. No iceoryx dependency.
//
// A running RouDi is not enough: iceoryx 2.0 creates its shared memory and sockets for
// RouDi's primary group, and a client whose primary (effective) group differs hangs in
// initRuntime until "Timeout registering at RouDi" and then aborts the process, even as
// root or as a supplementary member of the group. probe_roudi() compares the socket
// file's group with the caller's effective group and says so before any of that happens.
#pragma once

#include <sys/types.h>

namespace mocap::client {

inline constexpr const char* kRouDiSocketPath = "/tmp/roudi";

enum class RouDiStatus {
  kRunning,       // bound, and this process's effective group is the socket's group
  kNotRunning,    // no socket file, or nobody has it bound (stale)
  kNoPermission,  // the socket exists but connect() is refused (EACCES/EPERM)
  kWrongGroup,    // RouDi runs, but this process's primary group is not RouDi's
};

struct RouDiProbe {
  RouDiStatus status = RouDiStatus::kNotRunning;
  gid_t roudi_gid = 0;    // group of the socket file (when it exists)
  gid_t process_gid = 0;  // getegid() of this process
};

// Never blocks, allocates nothing.
RouDiProbe probe_roudi(const char* socket_path = kRouDiSocketPath) noexcept;

// True when a process has `socket_path` bound as a Unix datagram socket (any group).
bool roudi_running(const char* socket_path = kRouDiSocketPath) noexcept;

}  // namespace mocap::client
