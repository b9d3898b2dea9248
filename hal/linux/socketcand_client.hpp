#pragma once
/// hal::CanBus as a socketcand client in raw mode (github.com/linux-can/socketcand,
/// doc/protocol.md): the other node on the bus of `drive_hil --can socketcand:PORT`, for a host
/// tool on a machine without SocketCAN. The handshake (`< hi >`, `< open CHANNEL >` -> `< ok >`,
/// `< rawmode >` -> `< ok >`) blocks in open(); afterwards both directions are non-blocking:
///   try_send    -> `< send ID LEN B0 .. >`, the part TCP did not take kept for the next call
///   try_receive <- `< frame ID SECS.USECS DATA >`, whatever the reads' boundaries
/// Host tools only: it allocates and makes system calls.
#include <cstdint>
#include <memory>
#include <string>

#include "hal/can_bus.hpp"
#include "hal/linux/socketcand_text.hpp"

namespace imd::hal {

/// Where --socketcand PORT connects: the drive on this machine.
inline constexpr const char* kDefaultSocketcandHost = "127.0.0.1";

/// "PORT" (host kDefaultSocketcandHost), "HOST:PORT" or "[V6]:PORT" -> host and port, by the
/// same rules as imdrive's --socketcand. False and `error` naming `text` when it is none.
bool parse_socketcand_address(const std::string& text, std::string& host, uint16_t& port,
                              std::string& error);

class SocketcandClient final : public CanBus {
 public:
  /// Unsent text beyond which try_send refuses frames (the server reads too slowly).
  static constexpr std::size_t kMaxPendingOutput_bytes = 8192;

  /// Connects to `host` (a numeric IPv4 or IPv6 address, or localhost) and `port`, and opens
  /// `channel` in raw mode, within `timeout_ms` in all. nullptr and `error` on failure, e.g. "no
  /// socketcand server at 127.0.0.1:29536: connection refused; start drive_hil --can
  /// socketcand:29536".
  static std::unique_ptr<SocketcandClient> open(const std::string& host, uint16_t port,
                                                std::string& error,
                                                const std::string& channel = "can0",
                                                int timeout_ms = 2000);
  ~SocketcandClient();
  SocketcandClient(const SocketcandClient&) = delete;
  SocketcandClient& operator=(const SocketcandClient&) = delete;

  /// False if the frame is invalid, the connection is lost or too much is still unsent.
  bool try_send(const CanFrame& frame) noexcept override;
  /// The oldest frame received; server errors, 29-bit and malformed frames on the way are
  /// counted and skipped. False if none is waiting.
  bool try_receive(CanFrame& frame) noexcept override;

  /// Why the connection ended (the server closed it, a read or write failed); empty while it
  /// lasts. Nothing is sent or received after that.
  const std::string& lost() const noexcept { return lost_; }
  /// `< error ... >` messages from the server, and the last one's text.
  uint64_t server_errors() const noexcept { return server_errors_; }
  const std::string& last_server_error() const noexcept { return last_server_error_; }
  /// Messages skipped: 29-bit or malformed frames, anything unexpected.
  uint64_t skipped_messages() const noexcept { return skipped_messages_; }
  /// The socket, for poll(); stays owned by this object.
  int native_handle() const noexcept { return fd_; }
  /// The events to poll native_handle() for: POLLIN, and POLLOUT while a frame is partly
  /// unsent, so that the caller wakes to let try_receive write it rather than sleeping on it.
  short poll_events() const noexcept;
  /// "127.0.0.1:29536".
  const std::string& address() const noexcept { return address_; }

 private:
  SocketcandClient(int fd, std::string address) : fd_(fd), address_(std::move(address)) {}
  /// Writes what is pending; false once the connection is lost.
  bool flush() noexcept;
  /// Reads what has arrived into the reader; false if nothing did (or the connection is lost).
  bool read_some() noexcept;
  void lose(const std::string& why) noexcept;
  /// Waits for the handshake's answer `want`; false and `error` otherwise.
  bool expect(SocketcandReply::Kind want, const char* what, int64_t deadline_ms,
              std::string& error);

  int fd_;
  std::string address_;
  SocketcandReader reader_;
  std::string pending_;
  std::string lost_;
  uint64_t server_errors_ = 0;
  std::string last_server_error_;
  uint64_t skipped_messages_ = 0;
};

}  // namespace imd::hal
