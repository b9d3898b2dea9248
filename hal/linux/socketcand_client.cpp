#include "hal/linux/socketcand_client.hpp"
#include "hal/linux/socket_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace imd::hal {
namespace {

// Reads after the first that one try_receive makes: bounds it under a flood of skipped text.
constexpr int kMaxReadsPerReceive = 16;

int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// Non-blocking connect, waited for up to `timeout_ms`; the socket, or -1 and errno.
int connect_within(const sockaddr_storage& address, socklen_t length, int timeout_ms) {
  const int fd = ::socket(address.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), length) == 0) return fd;
  if (errno == EINPROGRESS) {
    pollfd p{fd, POLLOUT, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    int result = ready == 0 ? ETIMEDOUT : errno;
    socklen_t size = sizeof result;
    if (ready > 0 && ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &result, &size) == 0 && result == 0) {
      return fd;
    }
    errno = result;
  }
  const int saved = errno;
  ::close(fd);
  errno = saved;
  return -1;
}

}  // namespace

bool parse_socketcand_address(const std::string& text, std::string& host, uint16_t& port,
                              std::string& error) {
  // The same rules as imdrive's parse_host_port (tools/python/imdrive/bus_open.py).
  const std::size_t colon = text.rfind(':');
  const std::string port_text = colon == std::string::npos ? text : text.substr(colon + 1);
  host = colon == std::string::npos ? std::string(kDefaultSocketcandHost) : text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  const bool digits = !port_text.empty() && port_text.size() <= 5 &&
                      port_text.find_first_not_of("0123456789") == std::string::npos;
  const long value = digits ? std::strtol(port_text.c_str(), nullptr, 10) : 0;
  if (host.empty() || value < 1 || value > 65535) {
    error = "--socketcand " + text +
            ": expected PORT, HOST:PORT or [V6]:PORT with a port in 1..65535, e.g. "
            "127.0.0.1:29536";
    return false;
  }
  port = static_cast<uint16_t>(value);
  return true;
}

std::unique_ptr<SocketcandClient> SocketcandClient::open(const std::string& host, uint16_t port,
                                                         std::string& error,
                                                         const std::string& channel,
                                                         int timeout_ms) {
  const std::string address =
      (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port);
  sockaddr_storage storage{};
  socklen_t length = 0;
  if (!numeric_address(host, port, storage, length)) {
    error = "socketcand " + address + ": '" + host +
            "' is not a numeric IPv4 or IPv6 address (nor localhost)";
    return nullptr;
  }
  const int64_t deadline_ms = now_ms() + timeout_ms;
  const int fd = connect_within(storage, length, timeout_ms);
  if (fd < 0) {
    const int why = errno;
    error =
        why == ECONNREFUSED
            ? "no socketcand server at " + address +
                  ": connection refused; start drive_hil --can socketcand:" + std::to_string(port)
        : why == ETIMEDOUT ? "no socketcand server at " + address + ": no answer within " +
                                 std::to_string(timeout_ms) + " ms"
                           : "cannot connect to socketcand " + address + ": " + std::strerror(why);
    return nullptr;
  }
  const int one = 1;  // a command frame is one small write: send it now, not after an ack
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  std::unique_ptr<SocketcandClient> client(new SocketcandClient(fd, address));
  using Kind = SocketcandReply::Kind;
  if (!client->expect(Kind::hi, "the greeting < hi >", deadline_ms, error)) return nullptr;
  client->pending_ = "< open " + channel + " >";
  if (!client->expect(Kind::ok, ("open " + channel).c_str(), deadline_ms, error)) return nullptr;
  client->pending_ = "< rawmode >";
  if (!client->expect(Kind::ok, "rawmode", deadline_ms, error)) return nullptr;
  return client;
}

SocketcandClient::~SocketcandClient() {
  ::close(fd_);
}

bool SocketcandClient::expect(SocketcandReply::Kind want, const char* what, int64_t deadline_ms,
                              std::string& error) {
  const std::string where = "socketcand " + address_ + ": ";
  while (lost_.empty()) {
    if (!pending_.empty() && !flush()) break;
    if (const std::optional<SocketcandPiece> piece = reader_.next()) {
      const SocketcandReply reply = parse_socketcand_reply(piece->text);
      if (!piece->error && reply.kind == want) return pending_.empty() || flush();
      if (reply.kind == SocketcandReply::Kind::error && reply.text == "busy") {
        error = where + "busy: another client is connected (the server takes one at a time)";
        return false;
      }
      error = where +
              (reply.kind == SocketcandReply::Kind::error
                   ? std::string(what) + " refused: " + reply.text
                   : "handshake: expected " + std::string(what) + ", got < " + piece->text + " >");
      return false;
    }
    const int64_t left_ms = deadline_ms - now_ms();
    if (left_ms <= 0) {
      error = where + "no answer to " + what + " (is it a socketcand server?)";
      return false;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left_ms)) > 0) read_some();
  }
  error = where + "handshake: " + lost_;
  return false;
}

void SocketcandClient::lose(const std::string& why) noexcept {
  if (lost_.empty()) lost_ = why;
}

bool SocketcandClient::flush() noexcept {
  while (!pending_.empty() && lost_.empty()) {
    const ssize_t n = ::send(fd_, pending_.data(), pending_.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      pending_.erase(0, static_cast<std::size_t>(n));
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      break;
    } else if (n < 0 && errno != EINTR) {
      lose(std::string("send failed: ") + std::strerror(errno));
    }
  }
  return lost_.empty();
}

bool SocketcandClient::read_some() noexcept {
  if (!lost_.empty()) return false;
  char bytes[4096];
  const ssize_t n = ::recv(fd_, bytes, sizeof bytes, MSG_DONTWAIT);
  if (n > 0) {
    reader_.feed(std::string_view(bytes, static_cast<std::size_t>(n)));
    return true;
  }
  if (n == 0) {
    lose("the server closed the connection (drive_hil stopped?)");
  } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
    lose(std::string("receive failed: ") + std::strerror(errno));
  }
  return false;
}

short SocketcandClient::poll_events() const noexcept {
  return static_cast<short>(POLLIN | (pending_.empty() || !lost_.empty() ? 0 : POLLOUT));
}

bool SocketcandClient::try_send(const CanFrame& frame) noexcept {
  if (frame.id > 0x7FF || frame.length > 8 || !flush()) return false;
  if (pending_.size() > kMaxPendingOutput_bytes) return false;
  pending_ += format_socketcand_send(frame);
  return flush();
}

bool SocketcandClient::try_receive(CanFrame& frame) noexcept {
  flush();  // what an earlier try_send left over
  // After the last read, what it brought is still parsed: a frame it completed must not wait
  // in the reader while the caller sleeps on a socket with nothing more to come.
  for (int reads = 0;;) {
    const std::optional<SocketcandPiece> piece = reader_.next();
    if (!piece) {
      if (reads > kMaxReadsPerReceive || !read_some()) return false;
      ++reads;
      continue;
    }
    const SocketcandReply reply =
        piece->error ? SocketcandReply{} : parse_socketcand_reply(piece->text);
    switch (reply.kind) {
      case SocketcandReply::Kind::frame:
        frame = reply.frame;
        return true;
      case SocketcandReply::Kind::error:
        ++server_errors_;
        last_server_error_ = reply.text;
        break;
      case SocketcandReply::Kind::ok:
      case SocketcandReply::Kind::echo:
        break;
      default:
        ++skipped_messages_;
        break;
    }
  }
}

}  // namespace imd::hal
