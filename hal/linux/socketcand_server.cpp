#include "hal/linux/socketcand_server.hpp"
#include "hal/linux/socket_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

#include "hal/linux/socketcand_session.hpp"

namespace imd::hal {
namespace {

constexpr int kPollTimeout_ms = 1;
constexpr int kStopFlushTimeout_ms = 100;
constexpr int kListenBacklog = 4;
constexpr int kMaxReadsPerWakeup = 16;           // bounds one wake-up under a flood from the client
constexpr uint64_t kLoggedErrorsPerClient = 10;  // then they are only counted
constexpr std::string_view kBusy = "< error busy >";
// A peer that vanished without a FIN or RST (cable pulled, host powered off, NAT state lost)
// would hold the only client slot forever: probe an idle connection after 2 s, every 1 s, and
// give up after 3 unanswered probes (about 5 s); TCP_USER_TIMEOUT ends a connection whose
// written data stays unacknowledged as long. The drive's own command watchdog acts sooner.
constexpr int kKeepIdle_s = 2;
constexpr int kKeepInterval_s = 1;
constexpr int kKeepProbes = 3;
constexpr unsigned kUserTimeout_ms = 5000;
// Every client we know (imdrive, python-can, drive_monitor) is in raw mode within milliseconds
// of connecting; 3 s leaves room for a loaded machine and frees the slot taken by a port scan
// or by something that is not a socketcand client.
constexpr auto kRawModeDeadline = std::chrono::seconds(3);

/// "127.0.0.1:29536", "[::1]:29536".
std::string address_text(const sockaddr* address) {
  char host[INET6_ADDRSTRLEN] = "?";
  uint16_t port = 0;
  std::string text;
  if (address->sa_family == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(address);
    ::inet_ntop(AF_INET6, &v6->sin6_addr, host, sizeof host);
    port = ntohs(v6->sin6_port);
    text.append("[").append(host).append("]");
  } else {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(address);
    ::inet_ntop(AF_INET, &v4->sin_addr, host, sizeof host);
    port = ntohs(v4->sin_port);
    text.append(host);
  }
  return text.append(":").append(std::to_string(port));
}

bool passes(const std::vector<CanIdFilter>& filters, const CanFrame& frame) {
  if (filters.empty()) return true;
  for (const CanIdFilter& f : filters) {
    if ((frame.id & f.mask) == (f.id & f.mask)) return true;
  }
  return false;
}

}  // namespace

struct SocketcandServer::Client {
  int fd = -1;
  std::string peer;
  SocketcandSession session;
  std::string out;  ///< text not yet written
  std::chrono::steady_clock::time_point connected_at;
};

std::unique_ptr<SocketcandServer> SocketcandServer::open(const std::string& host, uint16_t port,
                                                         std::string& error,
                                                         const std::vector<CanIdFilter>& filters,
                                                         SocketcandLog log) {
  const std::string where = "socketcand " + host + ":" + std::to_string(port);
  sockaddr_storage address{};
  socklen_t address_length = 0;
  if (!numeric_address(host, port, address, address_length)) {
    error = where + ": '" + host +
            "' is not a numeric IPv4 or IPv6 address (e.g. 127.0.0.1, 0.0.0.0, ::1) or localhost";
    return nullptr;
  }
  const int fd = ::socket(address.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = where + ": socket: " + std::strerror(errno);
    return nullptr;
  }
  // A restarted drive_hil gets its port back at once, not after TIME_WAIT.
  const int on = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  const char* step = ::bind(fd, reinterpret_cast<sockaddr*>(&address), address_length) != 0 ? "bind"
                     : ::listen(fd, kListenBacklog) != 0 ? "listen"
                                                         : nullptr;
  if (step != nullptr) {
    error = where + ": " + step + ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  sockaddr_storage bound{};
  socklen_t length = sizeof bound;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length);
  error.clear();
  return std::unique_ptr<SocketcandServer>(new SocketcandServer(
      fd, address_text(reinterpret_cast<sockaddr*>(&bound)), filters, std::move(log)));
}

SocketcandServer::SocketcandServer(int listen_fd, std::string address,
                                   std::vector<CanIdFilter> filters, SocketcandLog log)
    : listen_fd_(listen_fd),
      address_(std::move(address)),
      filters_(std::move(filters)),
      log_(std::move(log)) {
  io_ = std::thread([this] { run_io(); });
}

SocketcandServer::~SocketcandServer() {
  flush(kStopFlushTimeout_ms);
  stop_.store(true);
  io_.join();
  drop_client();
  ::close(listen_fd_);
}

void SocketcandServer::run_io() noexcept {
  while (!stop_.load(std::memory_order_relaxed)) {
    pollfd watch[2] = {{listen_fd_, POLLIN, 0}, {-1, 0, 0}};
    if (client_) {
      watch[1].fd = client_->fd;
      // A client that does not read its answers is not read either: its requests wait in TCP,
      // and its output stays bounded.
      const bool readable = client_->out.size() < kMaxPendingOutput_bytes;
      watch[1].events =
          static_cast<short>((readable ? POLLIN : 0) | (client_->out.empty() ? 0 : POLLOUT));
    }
    ::poll(watch, 2, kPollTimeout_ms);
    // The client first: one that has just left makes room for the next in the same wake-up.
    if (client_ && (watch[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      read_client();
      // Answers leave before frames: a client that reads `< ok >` alone after `< rawmode >`
      // (python-can's does) gets it alone whenever the network allows.
      if (client_) write_client();
    }
    if (client_ && !client_->session.raw() &&
        std::chrono::steady_clock::now() - client_->connected_at > kRawModeDeadline) {
      clients_dropped_.fetch_add(1, std::memory_order_relaxed);
      if (log_) log_("client " + client_->peer + " dropped: not in raw mode within 3 s");
      drop_client();
    }
    if ((watch[0].revents & POLLIN) != 0) accept_clients();
    drain_tx();
    if (client_) write_client();
  }
}

void SocketcandServer::accept_clients() noexcept {
  while (true) {
    sockaddr_storage peer{};
    socklen_t length = sizeof peer;
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&peer), &length,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;  // none left (EAGAIN), or the peer gave up already
    const std::string who = address_text(reinterpret_cast<sockaddr*>(&peer));
    if (client_) read_client();  // it may have left since the poll (its end of stream waits)
    if (client_) {
      ::send(fd, kBusy.data(), kBusy.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      ::close(fd);
      clients_refused_.fetch_add(1, std::memory_order_relaxed);
      if (log_) log_("client " + who + " refused: " + client_->peer + " is connected");
      continue;
    }
    // Frames are small and latency matters more than packet count.
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    ::setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &kKeepIdle_s, sizeof kKeepIdle_s);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &kKeepInterval_s, sizeof kKeepInterval_s);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &kKeepProbes, sizeof kKeepProbes);
    ::setsockopt(fd, IPPROTO_TCP, TCP_USER_TIMEOUT, &kUserTimeout_ms, sizeof kUserTimeout_ms);
    client_ = std::make_unique<Client>();
    client_->fd = fd;
    client_->peer = who;
    client_->out = SocketcandSession::kGreeting;
    client_->connected_at = std::chrono::steady_clock::now();
    clients_.fetch_add(1, std::memory_order_relaxed);
    client_connected_.store(true);
    if (log_) log_("client " + who + " connected");
  }
}

void SocketcandServer::read_client() noexcept {
  char bytes[4096];
  std::vector<CanFrame> frames;
  for (int i = 0; i < kMaxReadsPerWakeup && client_; ++i) {
    if (client_->out.size() >= kMaxPendingOutput_bytes) return;  // until it reads its answers
    const ssize_t n = ::recv(client_->fd, bytes, sizeof bytes, 0);
    if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK)) {
      if (log_) {
        log_("client " + client_->peer +
             (n == 0 ? std::string(" left") : std::string(" lost: ") + std::strerror(errno)));
      }
      drop_client();
      return;
    }
    if (n < 0) {
      if (errno == EINTR) continue;
      return;  // all read
    }
    const uint64_t errors_before = client_->session.errors();
    frames.clear();
    client_->session.receive(std::string_view(bytes, static_cast<std::size_t>(n)), client_->out,
                             frames);
    for (const CanFrame& frame : frames) {
      if (!passes(filters_, frame)) {
        filtered_.fetch_add(1, std::memory_order_relaxed);
      } else if (rx_.try_push(frame)) {
        received_.fetch_add(1, std::memory_order_relaxed);
      } else {
        rx_dropped_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    uint64_t errors = errors_before;
    for (const std::string& text : client_->session.new_errors()) {
      client_errors_.fetch_add(1, std::memory_order_relaxed);
      if (log_ && ++errors <= kLoggedErrorsPerClient) {
        log_("client " + client_->peer + ": < error " + text + " >" +
             (errors == kLoggedErrorsPerClient ? " (further errors are only counted)" : ""));
      }
    }
    pending_output_bytes_.store(client_->out.size(), std::memory_order_relaxed);
    if (client_->out.size() > kMaxClientOutput_bytes) {
      clients_dropped_.fetch_add(1, std::memory_order_relaxed);
      if (log_) {
        log_("client " + client_->peer + " dropped: " + std::to_string(client_->out.size()) +
             " bytes of answers unread");
      }
      drop_client();
      return;
    }
  }
}

void SocketcandServer::drain_tx() noexcept {
  for (const CanFrame* next = tx_.front(); next != nullptr; next = tx_.front()) {
    if (!client_ || !client_->session.raw()) {
      tx_.pop();
      front_held_ = false;
      dropped_no_client_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (client_->out.size() >= kMaxPendingOutput_bytes) {
      if (!front_held_) tx_retries_.fetch_add(1, std::memory_order_relaxed);  // once a frame
      front_held_ = true;
      break;
    }
    timespec now{};
    ::clock_gettime(CLOCK_REALTIME, &now);  // socketcand stamps frames with the wall clock
    client_->out += format_socketcand_frame(*next, now.tv_sec, now.tv_nsec / 1000);
    // Stored before the pop, so that flush() never sees an empty ring and no pending text.
    pending_output_bytes_.store(client_->out.size(), std::memory_order_relaxed);
    tx_.pop();
    front_held_ = false;
    sent_.fetch_add(1, std::memory_order_relaxed);
  }
}

void SocketcandServer::write_client() noexcept {
  while (!client_->out.empty()) {
    const ssize_t n =
        ::send(client_->fd, client_->out.data(), client_->out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      client_->out.erase(0, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    if (log_) log_("client " + client_->peer + " lost: " + std::strerror(errno));
    drop_client();
    return;
  }
  pending_output_bytes_.store(client_->out.size(), std::memory_order_relaxed);
}

void SocketcandServer::drop_client() noexcept {
  if (!client_) return;
  ::close(client_->fd);
  client_.reset();
  client_connected_.store(false);
  pending_output_bytes_.store(0, std::memory_order_relaxed);
}

bool SocketcandServer::flush(int timeout_ms) noexcept {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (tx_.size() > 0 || pending_output_bytes_.load() > 0) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

QueuedCanCounters SocketcandServer::counters() const noexcept {
  QueuedCanCounters c;
  c.sent = sent_.load();
  c.received = received_.load();
  c.rx_dropped = rx_dropped_.load();
  c.tx_retries = tx_retries_.load();
  return c;
}

SocketcandCounters SocketcandServer::socketcand_counters() const noexcept {
  SocketcandCounters c;
  c.clients = clients_.load();
  c.clients_refused = clients_refused_.load();
  c.dropped_no_client = dropped_no_client_.load();
  c.client_errors = client_errors_.load();
  c.filtered = filtered_.load();
  c.clients_dropped = clients_dropped_.load();
  return c;
}

}  // namespace imd::hal
