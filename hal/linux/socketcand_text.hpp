#pragma once
/// The text of the socketcand protocol (github.com/linux-can/socketcand, doc/protocol.md), as
/// far as a raw-mode server and its client need it: every message is `< WORDS >` on a TCP
/// stream, with no line ends and no length prefix, so a message may arrive split over several
/// reads or many in one read. Runs in the server's I/O thread or in a host tool (it
/// allocates), never in the tick.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "hal/can_bus.hpp"

namespace imd::hal {

/// One piece of the client's stream: a whole message (the words between '<' and '>', trimmed)
/// or a stretch of text that is not one (`error` says what), to be answered `< error ... >`.
struct SocketcandPiece {
  std::string text;
  bool error = false;
};

/// Cuts a byte stream into messages, whatever the reads' boundaries.
class SocketcandReader {
 public:
  /// The longest message kept: `< send 7FF 8 FF FF FF FF FF FF FF FF >` is 38 characters.
  static constexpr std::size_t kMaxMessage_chars = 256;

  /// Appends received bytes.
  void feed(std::string_view bytes);
  /// The next whole message or error, oldest first; nothing until more bytes are fed. Text
  /// outside '<' ... '>' (other than white space), a '<' inside a message and a message
  /// longer than kMaxMessage_chars are errors; reading goes on at the next '<'.
  std::optional<SocketcandPiece> next();

 private:
  std::string buffer_;
};

/// What one client message asks.
struct SocketcandCommand {
  enum class Kind { open, rawmode, bcmmode, echo, send, unsupported, bad };
  Kind kind = Kind::bad;
  std::string channel;  ///< open: the bus name
  CanFrame frame;       ///< send: the frame, checked
  std::string error;    ///< unsupported, bad: why, for `< error ... >`
};

/// Parses the words of one message (SocketcandPiece::text). `send ID LEN B0 .. Bn` takes an
/// 11-bit identifier in hex (1 to 3 digits), LEN 0..8 and exactly LEN bytes of 1 or 2 hex
/// digits each; a 29-bit identifier (8 digits) is refused, the drive has none.
SocketcandCommand parse_socketcand(std::string_view words);

/// `< frame 123 1700000000.123456 1A220344 >`: the identifier as 3 upper-case hex digits, the
/// time, the data as contiguous upper-case hex (socketcand's own format; no data leaves two
/// spaces before '>', as socketcand writes it).
std::string format_socketcand_frame(const CanFrame& frame, int64_t seconds, int64_t micros);

/// What one server message says, as a client reads it (SocketcandPiece::text).
struct SocketcandReply {
  enum class Kind { frame, ok, hi, echo, error, other, bad };
  Kind kind = Kind::bad;
  CanFrame frame;    ///< frame: the frame, checked
  std::string text;  ///< error: the server's words; other, bad: what was not understood
};

/// Parses the words of one server message. `frame ID SECS.USECS [HEX ..]` takes an 11-bit
/// identifier (1 to 3 hex digits) and 0..8 bytes, as contiguous hex (what socketcand writes) or
/// a word per byte (what its protocol description shows), joined; a 29-bit identifier
/// (8 digits) is `other` (the drive has none), a malformed frame is `bad`.
SocketcandReply parse_socketcand_reply(std::string_view words);

/// `< send 123 4 1A 22 3 44 >` for a client: the identifier in hex, LEN, each byte in hex.
std::string format_socketcand_send(const CanFrame& frame);

/// `< error TEXT >`, with '<' and '>' in TEXT replaced so that it stays one message.
std::string format_socketcand_error(std::string_view text);

}  // namespace imd::hal
