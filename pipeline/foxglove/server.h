// Design: the Foxglove WebSocket server of the live view (Boost.Beast over Boost.Asio).
// It runs on its OWN io thread, never on the real-time threads: broadcast() only posts
// the message to that thread and returns. Bounded by construction:
//   - at most max_clients connections; one more gets an HTTP 503 and is closed;
//   - an HTTP request that is not a WebSocket upgrade offering "foxglove.websocket.v1"
//     gets an HTTP 400 and is closed; the handshake must finish within handshake_ms;
//   - incoming messages are limited to max_message_bytes (larger: connection closed);
//   - each client has a bounded outgoing queue (client_queue_depth messages): when full
//     the OLDEST waiting message is dropped and counted (per client and in total);
//   - a client whose pending write makes no progress for stall_ms is disconnected, so a
//     viewer that stops reading never holds a slot nor memory for long.
// Protocol violations (protocol.h) send one status message with the reason and close
// THAT connection. Nothing a client does reaches the tracker: the worst is its own
// disconnection. Binds 127.0.0.1 unless another address is configured.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/expected.h"
#include "pipeline/foxglove/protocol.h"

namespace mocap::foxglove {

struct ServerOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8765;  // 0: any free port (tests), see Server::port()
  int max_clients = 4;
  std::size_t max_message_bytes = 64 * 1024;  // incoming WebSocket message limit
  int client_queue_depth = 16;                // outgoing messages waiting per client
  int stall_ms = 3000;                        // a write pending longer ends the connection
  int handshake_ms = 5000;                    // HTTP + WebSocket handshake deadline
  std::string server_name = "mocap";
};

struct ServerCounters {
  std::uint64_t clients_accepted = 0;  // WebSocket sessions opened
  std::uint64_t clients_refused = 0;   // HTTP 400/503 answers (not Foxglove, too many)
  std::uint64_t protocol_errors = 0;   // sessions closed for a protocol violation
  std::uint64_t stalled_clients = 0;   // sessions closed because writes made no progress
  std::uint64_t messages_sent = 0;     // Message Data frames written (all clients)
  std::uint64_t messages_dropped = 0;  // dropped by full client queues (all clients)
  std::uint64_t broadcasts = 0;        // broadcast() calls
  int clients_active = 0;              // open WebSocket sessions now
};

// Parses "[ADDRESS:]PORT" (the CLI value of --foxglove) into options.address/port.
// One-line error naming `key` on failure.
Expected<void> parse_listen_address(const std::string& text, const std::string& key,
                                    ServerOptions& options);

class Server {
 public:
  // Binds and listens (errors: one line with the address); does not start the thread.
  static Expected<std::unique_ptr<Server>> create(const ServerOptions& options,
                                                  std::vector<ChannelInfo> channels);
  ~Server();  // stop()
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  void start();          // launches the io thread
  void stop() noexcept;  // closes every connection and joins the io thread (idempotent)
  std::uint16_t port() const noexcept;

  // Any thread, non-blocking: queues the payload for every client subscribed to the
  // channel (the payload is shared, not copied per client).
  void broadcast(std::uint32_t channel_id, std::uint64_t timestamp_ns,
                 std::shared_ptr<const std::string> payload);
  // How many clients subscribe to the channel (any thread, relaxed); 0 for no channel.
  int subscriber_count(std::uint32_t channel_id) const noexcept;
  bool has_subscribers(std::uint32_t channel_id) const noexcept {
    return subscriber_count(channel_id) > 0;
  }
  ServerCounters counters() const noexcept;

  struct Impl;

 private:
  explicit Server(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::foxglove
