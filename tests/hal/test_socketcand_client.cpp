// SocketcandClient against the project's own SocketcandServer on loopback TCP (the handshake,
// frames both ways, one client at a time, the connection lost when the server goes, the error
// when nothing listens), against a raw server that writes one byte at a time (partial reads),
// against one that writes a long burst at once (what the last read brought is parsed) or reads
// nothing for a while (POLLOUT asked for while a frame is unsent),
// and the client's side of the text: server messages parsed, `< send ... >` formatted.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "hal/linux/socketcand_client.hpp"
#include "hal/linux/socketcand_server.hpp"

namespace imd::hal {
namespace {

using namespace std::chrono_literals;
constexpr auto kWait = 5s;  // generous: ctest runs tests in parallel on a small machine

uint16_t port_of(const SocketcandServer& server) {
  const std::string& address = server.address();
  return static_cast<uint16_t>(std::stoi(address.substr(address.rfind(':') + 1)));
}

template <typename Bus>
bool receive_within(Bus& bus, CanFrame& frame) {
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  while (std::chrono::steady_clock::now() < deadline) {
    if (bus.try_receive(frame)) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

CanFrame frame_of(uint16_t id, std::initializer_list<uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  for (const uint8_t b : bytes) f.data[f.length++] = b;
  return f;
}

TEST(SocketcandClient, ExchangesFramesWithTheServer) {
  std::string error;
  const auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  const auto client = SocketcandClient::open("127.0.0.1", port_of(*server), error);
  ASSERT_TRUE(client) << error;

  ASSERT_TRUE(client->try_send(frame_of(0x021, {0x01, 0xAB, 0x00})));
  CanFrame got;
  ASSERT_TRUE(receive_within(*server, got));
  EXPECT_EQ(got.id, 0x021);
  ASSERT_EQ(got.length, 3);
  EXPECT_EQ(got.data[1], 0xAB);

  // The server sends only once the client is in raw mode; open() returns after that.
  ASSERT_TRUE(server->try_send(frame_of(0x701, {})));
  ASSERT_TRUE(server->try_send(frame_of(0x181, {1, 2, 3, 4, 5, 6, 7, 8})));
  ASSERT_TRUE(receive_within(*client, got));
  EXPECT_EQ(got.id, 0x701);
  EXPECT_EQ(got.length, 0);
  ASSERT_TRUE(receive_within(*client, got));
  EXPECT_EQ(got.id, 0x181);
  ASSERT_EQ(got.length, 8);
  EXPECT_EQ(got.data[7], 8);
  EXPECT_TRUE(client->lost().empty());
  EXPECT_EQ(client->server_errors(), 0u);
}

TEST(SocketcandClient, RefusesInvalidFrames) {
  std::string error;
  const auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  const auto client = SocketcandClient::open("127.0.0.1", port_of(*server), error);
  ASSERT_TRUE(client) << error;
  EXPECT_FALSE(client->try_send(frame_of(0x800, {})));
  CanFrame long_frame;
  long_frame.length = 9;
  EXPECT_FALSE(client->try_send(long_frame));
}

TEST(SocketcandClient, SaysWhatToStartWhenNothingListens) {
  std::string error;
  uint16_t port = 0;
  {
    const auto server = SocketcandServer::open("127.0.0.1", 0, error);
    ASSERT_TRUE(server) << error;
    port = port_of(*server);
  }  // closed: nothing listens on that port now
  EXPECT_FALSE(SocketcandClient::open("127.0.0.1", port, error));
  const std::string at = "127.0.0.1:" + std::to_string(port);
  EXPECT_EQ(error,
            "no socketcand server at " + at +
                ": connection refused; start drive_hil --can socketcand:" + std::to_string(port));
}

TEST(SocketcandClient, ASecondClientIsToldTheServerIsBusy) {
  std::string error;
  const auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  const auto first = SocketcandClient::open("127.0.0.1", port_of(*server), error);
  ASSERT_TRUE(first) << error;
  EXPECT_FALSE(SocketcandClient::open("127.0.0.1", port_of(*server), error));
  EXPECT_NE(error.find("busy: another client is connected"), std::string::npos) << error;
}

TEST(SocketcandClient, KnowsWhenTheServerHasGone) {
  std::string error;
  auto server = SocketcandServer::open("127.0.0.1", 0, error);
  ASSERT_TRUE(server) << error;
  const auto client = SocketcandClient::open("127.0.0.1", port_of(*server), error);
  ASSERT_TRUE(client) << error;
  server.reset();
  CanFrame got;
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  while (client->lost().empty() && std::chrono::steady_clock::now() < deadline) {
    EXPECT_FALSE(client->try_receive(got));
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ(client->lost(), "the server closed the connection (drive_hil stopped?)");
  EXPECT_FALSE(client->try_send(frame_of(0x021, {})));
}

/// A socket listening on a free loopback port (returned in `port`) for one client; a
/// `receive_buffer_bytes` above 0 sets its receive buffer (inherited by the accepted socket).
int listen_on_loopback(uint16_t& port, int receive_buffer_bytes = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer_bytes > 0) {
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), length), 0);
  EXPECT_EQ(::listen(fd, 1), 0);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  port = ntohs(address.sin_port);
  return fd;
}

/// A listening socket whose one client is written `text` one byte per send, with pauses, so
/// that every message arrives cut into pieces.
struct TricklingServer {
  int listen_fd = -1;
  uint16_t port = 0;
  std::thread thread;
  explicit TricklingServer(std::string text) {
    listen_fd = listen_on_loopback(port);
    thread = std::thread([this, text] {
      const int fd = ::accept(listen_fd, nullptr, nullptr);
      char answer[64];
      for (const char c : text) {
        if (c == '\x01') {  // the handshake's turn: wait for the client's message
          EXPECT_GT(::recv(fd, answer, sizeof answer, 0), 0);
          continue;
        }
        ::send(fd, &c, 1, MSG_NOSIGNAL);
        std::this_thread::sleep_for(100us);
      }
      std::this_thread::sleep_for(200ms);  // the client reads before the close
      ::close(fd);
    });
  }
  ~TricklingServer() {
    thread.join();
    ::close(listen_fd);
  }
};

/// A listening socket whose one client gets the handshake's answers, then (once `go`) `burst`
/// in one write; it then reads what the client sends once `drain` is set.
struct BurstServer {
  int listen_fd = -1;
  uint16_t port = 0;
  std::atomic<bool> go{false}, drain{false}, done{false};
  std::thread thread;
  explicit BurstServer(std::string burst) {
    listen_fd = listen_on_loopback(port, 4096);  // so that a client's unread sends soon fill TCP
    thread = std::thread([this, burst] {
      const int fd = ::accept(listen_fd, nullptr, nullptr);
      char bytes[4096];
      ::send(fd, "< hi >", 6, MSG_NOSIGNAL);
      EXPECT_GT(::recv(fd, bytes, sizeof bytes, 0), 0);
      ::send(fd, "< ok >", 6, MSG_NOSIGNAL);
      EXPECT_GT(::recv(fd, bytes, sizeof bytes, 0), 0);
      ::send(fd, "< ok >", 6, MSG_NOSIGNAL);
      while (!go && !done) std::this_thread::sleep_for(1ms);
      for (std::size_t at = 0; at < burst.size();) {
        const ssize_t n = ::send(fd, burst.data() + at, burst.size() - at, MSG_NOSIGNAL);
        if (n <= 0) break;
        at += static_cast<std::size_t>(n);
      }
      while (!drain && !done) std::this_thread::sleep_for(1ms);
      while (!done) {
        pollfd watch{fd, POLLIN, 0};
        if (::poll(&watch, 1, 10) == 1 && ::recv(fd, bytes, sizeof bytes, 0) <= 0) break;
      }
      ::close(fd);
    });
  }
  ~BurstServer() {
    done = true;
    thread.join();
    ::close(listen_fd);
  }
};

TEST(SocketcandClient, ParsesWhatItsLastReadBrought) {
  // try_receive reads at most 17 times (4096 bytes each) per call. The burst is exactly 17
  // reads long, skipped `< echo >` messages first and a frame last: the 17th read brings the
  // frame, and the call must return it rather than leave it in the reader while the socket is
  // empty (a caller polling the socket would then never learn of it).
  const std::string frame_text = "< frame 021 1.000001 0102 >";
  std::string burst;
  while (burst.size() + 8 + frame_text.size() <= 17 * 4096) burst += "< echo >";
  burst.append(17 * 4096 - frame_text.size() - burst.size(), ' ');
  burst += frame_text;
  ASSERT_EQ(burst.size(), 17u * 4096u);
  BurstServer server(burst);
  std::string error;
  const auto client = SocketcandClient::open("127.0.0.1", server.port, error);
  ASSERT_TRUE(client) << error;
  server.go = true;
  int queued_bytes = 0;  // the whole burst in the client's socket before the one call
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  while (queued_bytes < static_cast<int>(burst.size()) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(1ms);
    ::ioctl(client->native_handle(), FIONREAD, &queued_bytes);
  }
  ASSERT_EQ(queued_bytes, static_cast<int>(burst.size()));
  CanFrame got;
  ASSERT_TRUE(client->try_receive(got));
  EXPECT_EQ(got.id, 0x021);
  EXPECT_EQ(got.data[1], 0x02);
}

TEST(SocketcandClient, AsksToBeWokenWhileAFrameIsUnsent) {
  BurstServer server("");
  std::string error;
  const auto client = SocketcandClient::open("127.0.0.1", server.port, error);
  ASSERT_TRUE(client) << error;
  EXPECT_EQ(client->poll_events(), POLLIN);
  // A small kernel send buffer: left to autotuning, TCP took about 2.8 MB before it filled, and
  // draining that took a loaded 2-core machine past kWait (5 s; 1.6 s with four busy loops
  // beside it, 0.3 s idle). The client's own pending output is what the test is about.
  const int send_buffer_bytes = 4096;
  ASSERT_EQ(::setsockopt(client->native_handle(), SOL_SOCKET, SO_SNDBUF, &send_buffer_bytes,
                         sizeof send_buffer_bytes),
            0);
  // The server reads nothing: TCP fills, then the client keeps the rest pending.
  int sends = 0;
  while (client->try_send(frame_of(0x021, {1, 2, 3, 4, 5, 6, 7, 8})) && sends < 1'000'000) {
    ++sends;
  }
  ASSERT_TRUE(client->lost().empty()) << client->lost();
  EXPECT_EQ(client->poll_events(), POLLIN | POLLOUT);
  server.drain = true;
  // Woken for POLLOUT, try_receive writes what is pending; soon nothing is.
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  CanFrame got;
  while (client->poll_events() != POLLIN && std::chrono::steady_clock::now() < deadline) {
    pollfd watch{client->native_handle(), client->poll_events(), 0};
    ::poll(&watch, 1, 50);
    EXPECT_FALSE(client->try_receive(got));
  }
  EXPECT_EQ(client->poll_events(), POLLIN);
}

TEST(SocketcandClient, ReadsMessagesCutAnywhere) {
  // `< ok >` and the first frame are written together: the frame must not be lost.
  TricklingServer server("< hi >\x01< ok >\x01< ok >< frame 21 1.000001 0102 >  < frame 7FF 2.5 >");
  std::string error;
  const auto client = SocketcandClient::open("127.0.0.1", server.port, error);
  ASSERT_TRUE(client) << error;
  CanFrame got;
  ASSERT_TRUE(receive_within(*client, got));
  EXPECT_EQ(got.id, 0x021);
  ASSERT_EQ(got.length, 2);
  EXPECT_EQ(got.data[1], 0x02);
  ASSERT_TRUE(receive_within(*client, got));
  EXPECT_EQ(got.id, 0x7FF);
  EXPECT_EQ(got.length, 0);
}

TEST(SocketcandText, ParsesWhatAServerSays) {
  using Kind = SocketcandReply::Kind;
  EXPECT_EQ(parse_socketcand_reply("hi").kind, Kind::hi);
  EXPECT_EQ(parse_socketcand_reply("ok").kind, Kind::ok);
  const SocketcandReply error = parse_socketcand_reply("error busy");
  EXPECT_EQ(error.kind, Kind::error);
  EXPECT_EQ(error.text, "busy");
  const SocketcandReply frame = parse_socketcand_reply("frame 181 1700000000.123456 0A0b");
  ASSERT_EQ(frame.kind, Kind::frame);
  EXPECT_EQ(frame.frame.id, 0x181);
  ASSERT_EQ(frame.frame.length, 2);
  EXPECT_EQ(frame.frame.data[0], 0x0A);
  EXPECT_EQ(frame.frame.data[1], 0x0B);
  EXPECT_EQ(parse_socketcand_reply("frame 12345678 1.0 00").kind, Kind::other);  // 29-bit
  EXPECT_EQ(parse_socketcand_reply("frame 800 1.0").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 ABC").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 000102030405060708").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 0G").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("frame 1").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("hello").kind, Kind::other);
}

TEST(SocketcandText, ReadsTheDocumentedFrameWithAWordPerByte) {
  using Kind = SocketcandReply::Kind;
  // socketcand's doc/protocol.md shows this form; its server writes the contiguous one.
  const SocketcandReply frame = parse_socketcand_reply("frame 123 23.424242 11 22 33 44");
  ASSERT_EQ(frame.kind, Kind::frame) << frame.text;
  EXPECT_EQ(frame.frame.id, 0x123);
  ASSERT_EQ(frame.frame.length, 4);
  EXPECT_EQ(frame.frame.data[0], 0x11);
  EXPECT_EQ(frame.frame.data[3], 0x44);
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 11 22 33 44 55 66 77 88 99").kind, Kind::bad);
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 1 2").kind, Kind::bad);  // not 0x12
  EXPECT_EQ(parse_socketcand_reply("frame 1 1.0 11 2G").kind, Kind::bad);
}

TEST(SocketcandText, FormatsASendTheServerAccepts) {
  const CanFrame frame = frame_of(0x21, {0x01, 0xAB});
  const std::string text = format_socketcand_send(frame);
  EXPECT_EQ(text, "< send 021 2 01 AB >");
  const SocketcandCommand back = parse_socketcand(text.substr(1, text.size() - 2));
  ASSERT_EQ(back.kind, SocketcandCommand::Kind::send);
  EXPECT_EQ(back.frame.id, 0x21);
  EXPECT_EQ(back.frame.data[1], 0xAB);
  EXPECT_EQ(format_socketcand_send(frame_of(0x7FF, {})), "< send 7FF 0 >");
}

TEST(SocketcandAddress, TakesPortHostColonPortAndBracketedV6) {
  // The same forms as imdrive's --socketcand (tests/python/test_socketcand_bus.py).
  std::string host, error;
  uint16_t port = 0;
  ASSERT_TRUE(parse_socketcand_address("127.0.0.1:29536", host, port, error));
  EXPECT_EQ(host, "127.0.0.1");
  EXPECT_EQ(port, 29536);
  ASSERT_TRUE(parse_socketcand_address("[::1]:7", host, port, error));
  EXPECT_EQ(host, "::1");
  EXPECT_EQ(port, 7);
  ASSERT_TRUE(parse_socketcand_address("29536", host, port, error));
  EXPECT_EQ(host, "127.0.0.1");
  EXPECT_EQ(port, 29536);
  for (const char* bad : {"host:", ":5", "h:0", "h:70000", "h:12x", "h:+5", "h: 5", "0", ""}) {
    EXPECT_FALSE(parse_socketcand_address(bad, host, port, error)) << bad;
    EXPECT_EQ(error, std::string("--socketcand ") + bad +
                         ": expected PORT, HOST:PORT or [V6]:PORT with a port in 1..65535, "
                         "e.g. 127.0.0.1:29536");
  }
}

}  // namespace
}  // namespace imd::hal
