// SocketcandServer on loopback TCP: the handshake, frames both ways through the rings, the
// node filter, an error answered without harm, one client at a time, a new client after one
// has left, and the drive's frames dropped and counted while nobody listens.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "hal/linux/socketcand_server.hpp"

namespace imd::hal {
namespace {

using namespace std::chrono_literals;
constexpr auto kWait = 5s;  // generous: ctest runs tests in parallel on a small machine

uint16_t port_of(const SocketcandServer& server) {
  const std::string& address = server.address();
  return static_cast<uint16_t>(std::stoi(address.substr(address.rfind(':') + 1)));
}

/// A blocking client socket connected to the server.
struct Client {
  int fd = -1;
  std::string received;
  explicit Client(uint16_t port) {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  }
  ~Client() { close(); }
  void close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  void send(const std::string& text) {
    ASSERT_EQ(::send(fd, text.data(), text.size(), MSG_NOSIGNAL), ssize_t(text.size()));
  }
  /// Reads until `text` has arrived (true) or the stream ends or kWait passes (false).
  bool read_until(const std::string& text) {
    const auto deadline = std::chrono::steady_clock::now() + kWait;
    while (received.find(text) == std::string::npos) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      pollfd watch{fd, POLLIN, 0};
      if (::poll(&watch, 1, 50) <= 0) continue;
      char bytes[1024];
      const ssize_t n = ::recv(fd, bytes, sizeof bytes, 0);
      if (n <= 0) return false;
      received.append(bytes, static_cast<std::size_t>(n));
    }
    return true;
  }
  /// Whether the server closes the stream within kWait.
  bool closed_by_server() {
    char bytes[256];
    pollfd watch{fd, POLLIN, 0};
    return ::poll(&watch, 1, 5000) == 1 && ::recv(fd, bytes, sizeof bytes, 0) == 0;
  }
};

template <typename Predicate>
bool eventually(Predicate predicate) {
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  while (!predicate()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

CanFrame frame(uint16_t id, uint8_t b0, uint8_t b1) {
  CanFrame f;
  f.id = id;
  f.length = 2;
  f.data[0] = b0;
  f.data[1] = b1;
  return f;
}

TEST(socketcand_server, ServesOneClientAtATimeInRawMode) {
  std::string error;
  // Node 1's identifiers only, as drive_hil filters them.
  auto server = SocketcandServer::open("127.0.0.1", 0, error, {{0x20, 0x7E0}});
  ASSERT_TRUE(server) << error;
  EXPECT_EQ(server->address().rfind("127.0.0.1:", 0), 0u);

  // No client: the drive's frame is dropped and counted.
  ASSERT_TRUE(server->try_send(frame(0x30, 1, 2)));
  ASSERT_TRUE(eventually([&] { return server->socketcand_counters().dropped_no_client == 1; }));

  Client first(port_of(*server));
  ASSERT_TRUE(first.read_until("< hi >"));
  first.send("< open can0 >< raw");
  first.send("mode >");
  ASSERT_TRUE(first.read_until("< ok >< ok >"));

  ASSERT_TRUE(server->try_send(frame(0x30, 0xA1, 0x02)));
  ASSERT_TRUE(first.read_until(" A102 >"));
  EXPECT_NE(first.received.find("< frame 030 "), std::string::npos);

  first.send("< send 21 2 1 2 >< send 21 1 zz >< send 40 0 >");
  ASSERT_TRUE(first.read_until("< error send 21: data byte 0 'zz' is not 1 or 2 hex digits >"));
  CanFrame in;
  ASSERT_TRUE(eventually([&] { return server->try_receive(in); }));
  EXPECT_EQ(in.id, 0x21);
  EXPECT_EQ(in.length, 2);
  EXPECT_EQ(in.data[1], 0x02);
  ASSERT_TRUE(eventually([&] { return server->socketcand_counters().filtered == 1; }));
  EXPECT_FALSE(server->try_receive(in));  // 0x40 is another node's

  Client second(port_of(*server));
  EXPECT_TRUE(second.read_until("< error busy >"));
  EXPECT_TRUE(second.closed_by_server());

  first.close();
  Client third(port_of(*server));
  EXPECT_TRUE(third.read_until("< hi >"));

  const SocketcandCounters counters = server->socketcand_counters();
  EXPECT_EQ(counters.clients, 2u);
  EXPECT_EQ(counters.clients_refused, 1u);
  EXPECT_EQ(counters.client_errors, 1u);
  EXPECT_EQ(server->counters().sent, 1u);
  EXPECT_EQ(server->counters().received, 1u);
}

TEST(socketcand_server, NamesAnAddressInUse) {
  std::string error;
  auto first = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(first) << error;
  auto second = SocketcandServer::open("127.0.0.1", port_of(*first), error);
  EXPECT_FALSE(second);
  EXPECT_EQ(error, "socketcand 127.0.0.1:" + std::to_string(port_of(*first)) +
                       ": bind: Address already in use");
  EXPECT_FALSE(SocketcandServer::open("drive.example", 0, error));
  EXPECT_EQ(error,
            "socketcand drive.example:0: 'drive.example' is not a numeric IPv4 or IPv6 address "
            "(e.g. 127.0.0.1, 0.0.0.0, ::1) or localhost");
  auto v6 = SocketcandServer::open("::1", 0, error);
  if (v6) {  // where IPv6 is configured
    EXPECT_EQ(v6->address().rfind("[::1]:", 0), 0u);
  }
}

}  // namespace
}  // namespace imd::hal
