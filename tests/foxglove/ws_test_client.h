// Design: a small synchronous WebSocket client for the server tests (Boost.Beast), with
// a socket receive timeout so that a test never hangs on a read, plus a raw-TCP helper
// for non-WebSocket input. Test-only.
#pragma once

// clang-format off
#include <utility>  // first: Boost 1.74's asio/awaitable.hpp uses std::exchange
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
// clang-format on
#include <sys/socket.h>
#include <sys/time.h>

#include <optional>
#include <string>

namespace mocap::foxglove::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

inline void set_receive_timeout(tcp::socket& s, int ms) {
  timeval tv{ms / 1000, (ms % 1000) * 1000};
  ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
}

struct WsClient {
  asio::io_context ioc;
  websocket::stream<tcp::socket> ws{ioc};
  beast::flat_buffer buffer;
  std::string error;

  // Connects and handshakes offering `subprotocol`; false (and `error`) on failure.
  bool connect(std::uint16_t port, const std::string& subprotocol = "foxglove.websocket.v1",
               int receive_buffer_bytes = 0) {
    boost::system::error_code ec;
    ws.next_layer().open(tcp::v4(), ec);
    if (receive_buffer_bytes > 0) {
      ws.next_layer().set_option(asio::socket_base::receive_buffer_size(receive_buffer_bytes), ec);
    }
    ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port), ec);
    if (ec) return error = ec.message(), false;
    set_receive_timeout(ws.next_layer(), 3000);
    ws.set_option(websocket::stream_base::decorator([subprotocol](websocket::request_type& req) {
      req.set(beast::http::field::sec_websocket_protocol, subprotocol);
    }));
    websocket::response_type res;
    ws.handshake(res, "127.0.0.1", "/", ec);
    if (ec) return error = ec.message() + " (HTTP " + std::to_string(res.result_int()) + ")", false;
    return true;
  }
  // One message (text or binary) or nullopt on error/close (then `error`).
  std::optional<std::string> read(bool* is_text = nullptr) {
    boost::system::error_code ec;
    buffer.clear();
    ws.read(buffer, ec);
    if (ec) return error = ec.message(), std::nullopt;
    if (is_text) *is_text = ws.got_text();
    return beast::buffers_to_string(buffer.data());
  }
  bool send_text(const std::string& text) {
    boost::system::error_code ec;
    ws.text(true);
    ws.write(asio::buffer(text), ec);
    return !ec;
  }
  bool send_binary(const std::string& bytes) {
    boost::system::error_code ec;
    ws.binary(true);
    ws.write(asio::buffer(bytes), ec);
    return !ec;
  }
};

// Sends raw bytes over TCP and returns what the server answers before closing.
inline std::string raw_exchange(std::uint16_t port, const std::string& bytes) {
  asio::io_context ioc;
  tcp::socket s(ioc);
  boost::system::error_code ec;
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port), ec);
  if (ec) return "connect failed";
  set_receive_timeout(s, 3000);
  asio::write(s, asio::buffer(bytes), ec);
  std::string answer;
  char chunk[1024];
  for (;;) {
    const std::size_t n = s.read_some(asio::buffer(chunk), ec);
    answer.append(chunk, n);
    if (ec) break;
  }
  return answer;
}

}  // namespace mocap::foxglove::test
