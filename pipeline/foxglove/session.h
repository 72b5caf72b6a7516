// Design: internals of the Foxglove server (server.h), shared by server.cpp and
// session.cpp only: Server::Impl (the io_context, acceptor, open sessions, counters) and
// Session, one client connection driven entirely on the io thread: HTTP request ->
// refusal or WebSocket accept -> read loop + write pump with a bounded drop-oldest
// queue. Not part of the module's interface.
#pragma once

// clang-format off
#include <utility>  // first: Boost 1.74's asio/awaitable.hpp uses std::exchange
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
// clang-format on
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/camera_set.h"
#include "pipeline/foxglove/protocol.h"
#include "pipeline/foxglove/server.h"

namespace mocap::foxglove {

// The live view's channels: /tf, /markers, /joints, /bodies and one /<camera>/blobs per rig
// camera (encode.h; make_scene keeps at most kMaxCameras).
inline constexpr std::size_t kMaxChannels = 4 + static_cast<std::size_t>(kMaxCameras);
inline constexpr int kMaxPendingHandshakes = 16;  // connections still in their HTTP request

class Session;

struct Server::Impl {
  ServerOptions options;
  std::vector<ChannelInfo> channels;
  std::string server_info;  // JSON texts sent to every new client
  std::string advertise;
  std::uint16_t port = 0;  // bound port, set at create (read from any thread)
  boost::asio::io_context ioc{1};
  boost::asio::ip::tcp::acceptor acceptor{ioc};
  boost::asio::steady_timer tick_timer{ioc};
  std::thread thread;
  std::vector<std::shared_ptr<Session>> sessions;  // open WebSocket sessions (io thread)
  int pending_handshakes = 0;                      // sessions before their HTTP request (io)
  boost::asio::steady_timer accept_retry{ioc};     // after an accept error (EMFILE, ...)
  std::array<std::atomic<int>, kMaxChannels> subscribers{};
  struct {
    std::atomic<std::uint64_t> clients_accepted{0}, clients_refused{0}, protocol_errors{0},
        stalled_clients{0}, messages_sent{0}, messages_dropped{0}, broadcasts{0};
    std::atomic<int> clients_active{0};
  } counters;

  int channel_index(std::uint32_t channel_id) const noexcept;
  void accept_next();
  void tick();  // stall detection, every 100 ms
  void opened(const std::shared_ptr<Session>& session);
  void closed(const Session* session);
  void recount_subscribers();
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(Server::Impl& server, boost::asio::ip::tcp::socket socket);
  void start();
  // Queues one Message Data frame when the client subscribes to the channel.
  void send_data(std::uint32_t channel_id, std::uint64_t timestamp_ns,
                 const std::shared_ptr<const std::string>& payload);
  void check_stall(std::chrono::steady_clock::time_point now);
  const ClientProtocol& protocol() const noexcept { return protocol_; }

 private:
  struct Outgoing {
    bool text = false;
    std::array<std::uint8_t, kMessageDataHeaderBytes> header{};
    std::shared_ptr<const std::string> payload;
  };
  void on_request(boost::system::error_code ec);
  void refuse(boost::beast::http::status status, const std::string& why);
  void on_accept(boost::system::error_code ec);
  void read_next();
  void on_read(boost::system::error_code ec, std::size_t bytes);
  void violation(const std::string& reason);
  void enqueue(Outgoing message);
  void pump();
  void finish(const std::string& reason);
  void leave_pending() noexcept;

  Server::Impl& server_;
  boost::beast::websocket::stream<boost::asio::ip::tcp::socket> ws_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
  std::optional<boost::beast::http::response<boost::beast::http::string_body>> refusal_;
  boost::asio::steady_timer handshake_timer_;
  ClientProtocol protocol_;
  std::string remote_;
  std::deque<Outgoing> queue_;  // waiting, not in flight
  Outgoing inflight_;
  bool writing_ = false;
  bool open_ = false;     // WebSocket established and registered with the server
  bool closing_ = false;  // violation: drain, then close
  bool done_ = false;
  bool pending_ = false;  // counted in Server::Impl::pending_handshakes
  std::string close_reason_;
  std::chrono::steady_clock::time_point write_started_{};
  std::uint64_t sent_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace mocap::foxglove
