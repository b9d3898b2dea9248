// SocketcandServer on loopback TCP: the handshake, frames both ways through the rings, the
// node filter, an error answered without harm, one client at a time, a new client after one
// has left, and the drive's frames dropped and counted while nobody listens; the edges: a
// client that never reads (the drive's frames, its own answers), one that vanishes while
// frames are written to it, one that never reaches raw mode, and the destructor with a client.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fcntl.h>

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
  /// `receive_buffer_bytes` (0: the default) small makes a client that never reads fill TCP soon.
  explicit Client(uint16_t port, int receive_buffer_bytes = 0) {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer_bytes > 0) {
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
    }
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

/// A client in raw mode.
void enter_raw_mode(Client& client) {
  ASSERT_TRUE(client.read_until("< hi >"));
  client.send("< open can0 >< rawmode >");
  ASSERT_TRUE(client.read_until("< ok >< ok >"));
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

TEST(socketcand_server, BoundsTheOutputOfAClientThatNeverReads) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  Client slow(port_of(*server), 4096);
  enter_raw_mode(slow);
  // From here on the client reads nothing. The drive sends, at a pace the I/O thread keeps up
  // with, until TCP is full (the kernel's buffers take some MiB on loopback) and the output
  // stays at its limit; then as many again as the ring holds: those the ring refuses are the
  // drive's to count, as it counts telemetry it could not queue.
  uint64_t offered = 0, refused = 0;
  std::size_t most_pending_bytes = 0;
  const auto send_one = [&] {
    if (!server->try_send(frame(0x30, static_cast<uint8_t>(offered), 0))) ++refused;
    ++offered;
    most_pending_bytes = std::max(most_pending_bytes, server->pending_output_bytes());
  };
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  bool output_full = false;
  while (!output_full && std::chrono::steady_clock::now() < deadline) {
    for (int batch = 0; batch < 50; ++batch) {
      for (int i = 0; i < 64; ++i) send_one();
      std::this_thread::sleep_for(1ms);
    }
    std::this_thread::sleep_for(20ms);  // some wake-ups to write what TCP still takes
    output_full = server->pending_output_bytes() >= SocketcandServer::kMaxPendingOutput_bytes;
  }
  ASSERT_TRUE(output_full) << "TCP still takes frames after " << offered;
  for (std::size_t i = 0; i < 2 * SocketcandServer::kRingFrames; ++i) send_one();
  std::this_thread::sleep_for(100ms);
  most_pending_bytes = std::max(most_pending_bytes, server->pending_output_bytes());
  const QueuedCanCounters counters = server->counters();
  EXPECT_GT(refused, 0u);
  // One frame of text (~32 bytes) may pass the limit.
  EXPECT_LE(most_pending_bytes, SocketcandServer::kMaxPendingOutput_bytes + 64);
  const uint64_t queued = offered - refused - counters.sent;  // still in the ring
  EXPECT_GT(queued, 0u);
  EXPECT_LE(queued, SocketcandServer::kRingFrames);
  // tx_retries counts frames, not wake-ups: another 300 (1 ms) wake-ups with the same frame
  // held back count nothing more.
  EXPECT_GE(counters.tx_retries, 1u);
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(server->counters().tx_retries, counters.tx_retries);
  EXPECT_TRUE(server->client_connected());
}

TEST(socketcand_server, StopsReadingAClientThatLeavesItsAnswersUnread) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  Client flooder(port_of(*server), 4096);
  ASSERT_TRUE(flooder.read_until("< hi >"));
  // `< echo >` commands, each answered `< echo >`, sent without reading a byte: without the
  // gate the server would read them all and hold the answers TCP cannot take. The kernel's
  // buffers on loopback absorb megabytes first, and how fast depends on the machine (a
  // sanitizer build on a busy one is slow), so the flood goes on until the server's output
  // reaches the limit, with a generous deadline, and is then watched for a while.
  ::fcntl(flooder.fd, F_SETFL, ::fcntl(flooder.fd, F_GETFL) | O_NONBLOCK);
  std::string echoes;
  for (int i = 0; i < 512; ++i) echoes += "< echo >";
  std::size_t most_pending_bytes = 0;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (most_pending_bytes < SocketcandServer::kMaxPendingOutput_bytes &&
         std::chrono::steady_clock::now() < deadline) {
    const ssize_t n = ::send(flooder.fd, echoes.data(), echoes.size(), MSG_NOSIGNAL);
    if (n <= 0) std::this_thread::sleep_for(1ms);  // TCP is full: the server stopped reading
    most_pending_bytes = std::max(most_pending_bytes, server->pending_output_bytes());
  }
  const auto watch_end = std::chrono::steady_clock::now() + 300ms;  // ~100s of server wake-ups
  while (std::chrono::steady_clock::now() < watch_end) {
    if (::send(flooder.fd, echoes.data(), echoes.size(), MSG_NOSIGNAL) <= 0)
      std::this_thread::sleep_for(1ms);
    most_pending_bytes = std::max(most_pending_bytes, server->pending_output_bytes());
  }
  EXPECT_GE(most_pending_bytes, SocketcandServer::kMaxPendingOutput_bytes);  // it was tested
  // Past the limit come at most the answers to one 4096-byte read (`< echo >` for each 8).
  EXPECT_LE(most_pending_bytes, SocketcandServer::kMaxPendingOutput_bytes + 4096);
  EXPECT_TRUE(server->client_connected());
  EXPECT_EQ(server->socketcand_counters().clients_dropped, 0u);
}

TEST(socketcand_server, DropsAClientThatVanishesWhileFramesAreWritten) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  {
    Client leaving(port_of(*server));
    enter_raw_mode(leaving);
    for (int i = 0; i < 2000; ++i) server->try_send(frame(0x30, 1, 2));
    // A close with unread data sends a reset: the server's next write fails.
    const linger reset{1, 0};
    ::setsockopt(leaving.fd, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
  }
  for (int i = 0; i < 2000; ++i) server->try_send(frame(0x30, 1, 2));
  ASSERT_TRUE(eventually([&] { return !server->client_connected(); }));
  ASSERT_TRUE(eventually([&] { return server->socketcand_counters().dropped_no_client > 0; }));
  Client next(port_of(*server));
  enter_raw_mode(next);
  ASSERT_TRUE(server->try_send(frame(0x31, 0xBE, 0xEF)));
  EXPECT_TRUE(next.read_until(" BEEF >"));
}

TEST(socketcand_server, DropsAClientThatNeverReachesRawMode) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  Client idle(port_of(*server));
  ASSERT_TRUE(idle.read_until("< hi >"));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(idle.closed_by_server());  // after 3 s; closed_by_server waits up to 5 s
  EXPECT_GE(std::chrono::steady_clock::now() - start, 2500ms);
  EXPECT_EQ(server->socketcand_counters().clients_dropped, 1u);
  Client next(port_of(*server));
  EXPECT_TRUE(next.read_until("< hi >"));
}

TEST(socketcand_server, DestructorSendsWhatIsQueuedAndClosesARawClient) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  Client reader(port_of(*server));
  enter_raw_mode(reader);
  ASSERT_TRUE(server->try_send(frame(0x30, 0xCA, 0xFE)));
  const auto start = std::chrono::steady_clock::now();
  server.reset();
  // The destructor waits at most 100 ms for the queue; 2 s allows for a loaded machine.
  EXPECT_LT(std::chrono::steady_clock::now() - start, 2s);
  EXPECT_TRUE(reader.read_until(" CAFE >"));
  EXPECT_TRUE(reader.closed_by_server());
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
