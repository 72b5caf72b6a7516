// Design: see session.h and server.h. Every function runs on the io thread. Completion
// handlers hold a shared_ptr to their session, so a session lives until its last
// operation completes; finish() is idempotent and closes the socket, which completes
// every pending operation with an error.
#include "pipeline/foxglove/session.h"

#include <cstdio>

namespace mocap::foxglove {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using error_code = boost::system::error_code;

namespace {
std::vector<std::uint32_t> channel_ids(const std::vector<ChannelInfo>& channels) {
  std::vector<std::uint32_t> ids;
  for (const ChannelInfo& c : channels) ids.push_back(c.id);
  return ids;
}

// True when the comma-separated Sec-WebSocket-Protocol list offers ours.
bool offers_subprotocol(beast::string_view offered) {
  const std::string_view list(offered.data(), offered.size());
  std::size_t begin = 0;
  while (begin <= list.size()) {
    std::size_t end = list.find(',', begin);
    if (end == std::string_view::npos) end = list.size();
    std::string_view item = list.substr(begin, end - begin);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (item == kSubprotocol) return true;
    begin = end + 1;
  }
  return false;
}
}  // namespace

Session::Session(Server::Impl& server, asio::ip::tcp::socket socket)
    : server_(server),
      ws_(std::move(socket)),
      handshake_timer_(server.ioc),
      protocol_(channel_ids(server.channels)) {
  error_code ec;
  const auto endpoint = ws_.next_layer().remote_endpoint(ec);
  remote_ = ec ? std::string("?")
               : endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
}

void Session::start() {
  pending_ = true;
  ++server_.pending_handshakes;
  handshake_timer_.expires_after(std::chrono::milliseconds(server_.options.handshake_ms));
  handshake_timer_.async_wait([self = shared_from_this()](error_code ec) {
    if (!ec && !self->open_) self->finish("handshake timeout");
  });
  parser_.emplace();
  parser_->header_limit(8 * 1024);
  parser_->body_limit(4 * 1024);
  http::async_read(
      ws_.next_layer(), buffer_, *parser_,
      [self = shared_from_this()](error_code ec, std::size_t) { self->on_request(ec); });
}

void Session::leave_pending() noexcept {
  if (!pending_) return;
  pending_ = false;
  --server_.pending_handshakes;
}

void Session::on_request(error_code ec) {
  leave_pending();
  if (ec) return finish("bad HTTP request: " + ec.message());
  const auto& req = parser_->get();
  if (!websocket::is_upgrade(req)) {
    return refuse(
        http::status::bad_request,
        "mocap: this port serves the Foxglove WebSocket protocol (foxglove.websocket.v1)");
  }
  if (!offers_subprotocol(req[http::field::sec_websocket_protocol])) {
    return refuse(http::status::bad_request,
                  "mocap: the WebSocket subprotocol must be foxglove.websocket.v1");
  }
  if (static_cast<int>(server_.sessions.size()) >= server_.options.max_clients) {
    return refuse(
        http::status::service_unavailable,
        "mocap: too many viewers (limit " + std::to_string(server_.options.max_clients) + ")");
  }
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
    res.set(http::field::sec_websocket_protocol, kSubprotocol);
    res.set(http::field::server, "mocap");
  }));
  ws_.read_message_max(server_.options.max_message_bytes);
  ws_.auto_fragment(false);
  open_ = true;  // counts against max_clients from now on
  server_.opened(shared_from_this());
  ws_.async_accept(req, [self = shared_from_this()](error_code e) { self->on_accept(e); });
}

void Session::refuse(http::status status, const std::string& why) {
  server_.counters.clients_refused.fetch_add(1, std::memory_order_relaxed);
  refusal_.emplace(status, parser_->get().version());
  refusal_->set(http::field::server, "mocap");
  refusal_->set(http::field::content_type, "text/plain");
  refusal_->keep_alive(false);
  refusal_->body() = why + "\n";
  refusal_->prepare_payload();
  http::async_write(
      ws_.next_layer(), *refusal_,
      [self = shared_from_this(), why](error_code, std::size_t) { self->finish(why); });
}

void Session::on_accept(error_code ec) {
  if (ec) return finish("WebSocket handshake failed: " + ec.message());
  handshake_timer_.cancel();
  buffer_.clear();
  enqueue(Outgoing{true, {}, std::make_shared<const std::string>(server_.server_info)});
  enqueue(Outgoing{true, {}, std::make_shared<const std::string>(server_.advertise)});
  read_next();
}

void Session::read_next() {
  ws_.async_read(
      buffer_, [self = shared_from_this()](error_code ec, std::size_t n) { self->on_read(ec, n); });
}

void Session::on_read(error_code ec, std::size_t bytes) {
  if (done_ || closing_) return;
  if (ec == websocket::error::closed) return finish("closed by the viewer");
  if (ec == websocket::error::message_too_big) {
    // Beast has already sent the close frame (code 1009, too big): just count and end.
    server_.counters.protocol_errors.fetch_add(1, std::memory_order_relaxed);
    return finish("protocol violation: message larger than " +
                  std::to_string(server_.options.max_message_bytes) + " bytes");
  }
  if (ec) return finish("read failed: " + ec.message());
  bool ok = false;
  if (ws_.got_text()) {
    const auto data = buffer_.cdata();
    ok = protocol_.on_text(std::string_view(static_cast<const char*>(data.data()), data.size()));
  } else {
    ok = protocol_.on_binary(bytes);
  }
  buffer_.consume(buffer_.size());
  if (!ok) return violation(protocol_.error());
  server_.recount_subscribers();
  read_next();
}

void Session::violation(const std::string& reason) {
  server_.counters.protocol_errors.fetch_add(1, std::memory_order_relaxed);
  closing_ = true;
  close_reason_ = "protocol violation: " + reason;
  dropped_ += queue_.size();
  server_.counters.messages_dropped.fetch_add(queue_.size(), std::memory_order_relaxed);
  queue_.clear();
  queue_.push_back(Outgoing{true,
                            {},
                            std::make_shared<const std::string>(
                                status_json(StatusLevel::kError, "mocap: " + close_reason_))});
  pump();
}

void Session::send_data(std::uint32_t channel_id, std::uint64_t timestamp_ns,
                        const std::shared_ptr<const std::string>& payload) {
  std::uint32_t subscription = 0;
  if (!open_ || closing_ || done_ || !protocol_.subscription_for(channel_id, subscription)) return;
  enqueue(Outgoing{false, message_data_header(subscription, timestamp_ns), payload});
}

void Session::enqueue(Outgoing message) {
  if (static_cast<int>(queue_.size()) >= server_.options.client_queue_depth) {
    queue_.pop_front();  // drop-oldest: the viewer wants the newest state
    ++dropped_;
    server_.counters.messages_dropped.fetch_add(1, std::memory_order_relaxed);
  }
  queue_.push_back(std::move(message));
  pump();
}

void Session::pump() {
  if (writing_ || done_) return;
  if (queue_.empty()) {
    if (closing_) {
      writing_ = true;  // the close handshake counts as a pending write (stall check)
      write_started_ = std::chrono::steady_clock::now();
      ws_.async_close(websocket::close_code::policy_error, [self = shared_from_this()](error_code) {
        self->finish(self->close_reason_);
      });
    }
    return;
  }
  inflight_ = std::move(queue_.front());
  queue_.pop_front();
  writing_ = true;
  write_started_ = std::chrono::steady_clock::now();
  ws_.text(inflight_.text);
  auto done = [self = shared_from_this()](error_code ec, std::size_t) {
    self->writing_ = false;
    if (ec) return self->finish("write failed: " + ec.message());
    if (!self->inflight_.text) {
      ++self->sent_;
      self->server_.counters.messages_sent.fetch_add(1, std::memory_order_relaxed);
    }
    self->inflight_.payload.reset();
    self->pump();
  };
  if (inflight_.text) {
    ws_.async_write(asio::buffer(*inflight_.payload), std::move(done));
  } else {
    const std::array<asio::const_buffer, 2> frame{asio::buffer(inflight_.header),
                                                  asio::buffer(*inflight_.payload)};
    ws_.async_write(frame, std::move(done));
  }
}

void Session::check_stall(std::chrono::steady_clock::time_point now) {
  if (!writing_ || done_) return;
  if (now - write_started_ > std::chrono::milliseconds(server_.options.stall_ms)) {
    server_.counters.stalled_clients.fetch_add(1, std::memory_order_relaxed);
    finish("stalled: no write progress for " + std::to_string(server_.options.stall_ms) + " ms");
  }
}

void Session::finish(const std::string& reason) {
  if (done_) return;
  done_ = true;
  leave_pending();
  handshake_timer_.cancel();
  error_code ec;
  ws_.next_layer().shutdown(asio::ip::tcp::socket::shutdown_both, ec);
  ws_.next_layer().close(ec);
  if (open_) {
    server_.closed(this);
    // Not the real-time path: the io thread reports each viewer's end once.
    std::fprintf(stderr,
                 "foxglove: viewer %s disconnected (%s): %llu messages sent, %llu dropped\n",
                 remote_.c_str(), reason.c_str(), static_cast<unsigned long long>(sent_),
                 static_cast<unsigned long long>(dropped_));
  }
}

}  // namespace mocap::foxglove
