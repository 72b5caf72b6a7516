// Design: see server.h. One io_context on one thread; every session object is touched
// only on that thread, so sessions need no locks; the only cross-thread state is the
// atomic counters and the per-channel subscriber counts (relaxed: they are statistics
// and a hint to skip encoding, a stale value costs at most one encoded message).
// The session state machine: HTTP request (deadline) -> refuse (400/503) | WebSocket
// accept -> serverInfo + advertise -> read loop (protocol.h) and write pump; a violation
// queues a status message, then closes; any error or a stalled write ends the session.
#include "pipeline/foxglove/server.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "core/listen_address.h"
#include "pipeline/foxglove/session.h"

namespace mocap::foxglove {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

Expected<void> parse_listen_address(const std::string& text, const std::string& key,
                                    ServerOptions& options) {
  auto a = mocap::parse_listen_address(text, key, options.address, IpFamilies::kIpv4AndIpv6);
  if (!a) return a.error();
  options.address = a->address;
  options.port = a->port;
  return {};
}

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() { stop(); }

Expected<std::unique_ptr<Server>> Server::create(const ServerOptions& options,
                                                 std::vector<ChannelInfo> channels) {
  const std::string key = "foxglove";
  if (options.max_clients < 1 || options.client_queue_depth < 1 ||
      options.max_message_bytes < 1024 || options.stall_ms < 1 || options.handshake_ms < 1) {
    return make_error(key, "", "limits must be positive (message limit >= 1024 bytes)");
  }
  if (channels.size() > kMaxChannels) {
    return make_error(key, "", "more than " + std::to_string(kMaxChannels) + " channels");
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->channels = std::move(channels);
  impl->server_info = server_info_json(options.server_name, "mocap-" + std::to_string(::getpid()));
  impl->advertise = advertise_json(impl->channels);
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.address, ec);
  if (ec) return make_error(key, options.address, "not an IP address");
  const tcp::endpoint endpoint(address, options.port);
  const std::string where = options.address + ":" + std::to_string(options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl->acceptor.bind(endpoint, ec);
  if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return make_error(key, where, "cannot listen: " + ec.message());
  impl->port = impl->acceptor.local_endpoint(ec).port();  // the bound port (also for port 0)
  return std::unique_ptr<Server>(new Server(std::move(impl)));
}

void Server::start() {
  if (impl_->thread.joinable()) return;
  impl_->accept_next();
  impl_->tick();
  impl_->thread = std::thread([impl = impl_.get()] { impl->ioc.run(); });
}

void Server::stop() noexcept {
  if (!impl_) return;
  impl_->ioc.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::uint16_t Server::port() const noexcept { return impl_->port; }

void Server::broadcast(std::uint32_t channel_id, std::uint64_t timestamp_ns,
                       std::shared_ptr<const std::string> payload) {
  impl_->counters.broadcasts.fetch_add(1, std::memory_order_relaxed);
  asio::post(impl_->ioc, [impl = impl_.get(), channel_id, timestamp_ns, p = std::move(payload)] {
    for (const auto& session : impl->sessions) session->send_data(channel_id, timestamp_ns, p);
  });
}

int Server::subscriber_count(std::uint32_t channel_id) const noexcept {
  const int i = impl_->channel_index(channel_id);
  return i >= 0 ? static_cast<int>(impl_->subscribers[i].load(std::memory_order_relaxed)) : 0;
}

ServerCounters Server::counters() const noexcept {
  const auto& c = impl_->counters;
  ServerCounters out;
  out.clients_accepted = c.clients_accepted.load(std::memory_order_relaxed);
  out.clients_refused = c.clients_refused.load(std::memory_order_relaxed);
  out.protocol_errors = c.protocol_errors.load(std::memory_order_relaxed);
  out.stalled_clients = c.stalled_clients.load(std::memory_order_relaxed);
  out.messages_sent = c.messages_sent.load(std::memory_order_relaxed);
  out.messages_dropped = c.messages_dropped.load(std::memory_order_relaxed);
  out.broadcasts = c.broadcasts.load(std::memory_order_relaxed);
  out.clients_active = c.clients_active.load(std::memory_order_relaxed);
  return out;
}

// --- Impl (io thread) ---

int Server::Impl::channel_index(std::uint32_t channel_id) const noexcept {
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (channels[i].id == channel_id) return static_cast<int>(i);
  }
  return -1;
}

void Server::Impl::accept_next() {
  acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {  // EMFILE, ENFILE, ...: retry later instead of spinning; never stop serving
      accept_retry.expires_after(std::chrono::milliseconds(100));
      accept_retry.async_wait([this](boost::system::error_code e) {
        if (!e) accept_next();
      });
      return;
    }
    if (pending_handshakes >= kMaxPendingHandshakes) {
      // Many half-open connections (a scan or a flood): drop this one unanswered.
      counters.clients_refused.fetch_add(1, std::memory_order_relaxed);
      boost::system::error_code ignored;
      socket.close(ignored);
    } else {
      std::make_shared<Session>(*this, std::move(socket))->start();
    }
    accept_next();
  });
}

void Server::Impl::tick() {
  tick_timer.expires_after(std::chrono::milliseconds(100));
  tick_timer.async_wait([this](boost::system::error_code ec) {
    if (ec) return;
    const auto now = std::chrono::steady_clock::now();
    // Copy: a stalled session removes itself from `sessions` while we iterate.
    const auto snapshot = sessions;
    for (const auto& session : snapshot) session->check_stall(now);
    tick();
  });
}

void Server::Impl::opened(const std::shared_ptr<Session>& session) {
  sessions.push_back(session);
  counters.clients_accepted.fetch_add(1, std::memory_order_relaxed);
  counters.clients_active.store(static_cast<int>(sessions.size()), std::memory_order_relaxed);
}

void Server::Impl::closed(const Session* session) {
  for (auto it = sessions.begin(); it != sessions.end(); ++it) {
    if (it->get() == session) {
      sessions.erase(it);
      break;
    }
  }
  counters.clients_active.store(static_cast<int>(sessions.size()), std::memory_order_relaxed);
  recount_subscribers();
}

void Server::Impl::recount_subscribers() {
  for (std::size_t i = 0; i < channels.size(); ++i) {
    int n = 0;
    for (const auto& s : sessions) {
      std::uint32_t unused = 0;
      n += s->protocol().subscription_for(channels[i].id, unused) ? 1 : 0;
    }
    subscribers[i].store(n, std::memory_order_relaxed);
  }
}

}  // namespace mocap::foxglove
