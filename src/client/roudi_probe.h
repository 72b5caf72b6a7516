// Design: a non-blocking check that the iceoryx daemon RouDi runs, done BEFORE
// iox::runtime::PoshRuntime::initRuntime, which blocks forever without RouDi (iceoryx
// 2.0.3). RouDi listens on the Unix datagram socket /tmp/roudi; connect() on a datagram
// socket never blocks: it succeeds when a process has the address bound, and fails with
// ECONNREFUSED (stale file) or ENOENT (no file) otherwise. No iceoryx dependency.
#pragma once

namespace mocap::client {

inline constexpr const char* kRouDiSocketPath = "/tmp/roudi";

// True when a process has `socket_path` bound as a Unix datagram socket.
bool roudi_running(const char* socket_path = kRouDiSocketPath) noexcept;

}  // namespace mocap::client
