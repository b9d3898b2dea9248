#pragma once
/// The frame field of a candump `-L` line, as can-utils writes it (lib.c, snprintf_canframe):
///
///     022#0103000000000000      classic data frame, 11-bit identifier (3 hex digits)
///     18FF0001#0102             classic data frame, 29-bit identifier (8 hex digits)
///     022#R  022#R3             remote request, with the requested length when not 0
///     022#1122334455667788_E    8 data bytes sent with a raw DLC of 9..15 ("_" and one digit)
///     022##5AABB                CAN FD: "##", one hex digit of flags (BRS 1, ESI 2, FDF 4),
///                               then 0..8, 12, 16, 20, 24, 32, 48 or 64 data bytes
///     20000004#0004000000000000 error frame: 8 digits with CAN_ERR_FLAG (20000000) set; the
///                               other bits are the error class, the data its details
///
/// Anything else is an error that says what is wrong and quotes the offending text. The parser
/// never throws on malformed input.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "hal/can_bus.hpp"

namespace imd::can_log {

/// What a frame field holds.
enum class FrameType : uint8_t {
  data,    ///< a classic CAN data frame
  remote,  ///< a classic remote request (no data; `length` is the requested length)
  fd,      ///< a CAN FD frame
  error,   ///< an error frame the controller reported (no frame was on the bus)
};

/// One frame as a candump log holds it; wider than hal::CanFrame, which carries only what the
/// drive's protocol uses.
struct LogFrame {
  FrameType type = FrameType::data;
  bool extended = false;  ///< a 29-bit identifier (never set for an error frame)
  uint32_t id = 0;        ///< 11 or 29 bits; an error frame: its error class (CAN_ERR_MASK bits)
  uint8_t length = 0;     ///< data bytes: 0..8 (classic, error), 0..64 (FD); remote: requested
  uint8_t raw_dlc = 0;    ///< a classic 8-byte frame sent with DLC 9..15 ("_X"), else 0
  uint8_t fd_flags = 0;   ///< the FD flags digit, 0..15
  std::array<uint8_t, 64> data{};
};

/// Marks an error frame's identifier in the log (CAN_ERR_FLAG).
inline constexpr uint32_t kErrorFlag = 0x20000000;

/// What is wrong with a line (one kind per check, so that tests and tools can tell them apart).
enum class ParseErrorKind : uint8_t {
  empty_line,
  bad_timestamp,     ///< not "(SECONDS.MICROS)" with 6 decimals (or 9, candump -N)
  bad_separator,     ///< fields not separated as candump separates them
  missing_field,     ///< the line ends before the interface or the frame
  bad_interface,     ///< empty, too long, or containing control characters
  missing_hash,      ///< no '#' between identifier and data
  bad_identifier,    ///< not 3 or 8 hex digits
  identifier_range,  ///< 3 digits above 7FF, or 8 digits above 3FFFFFFF
  bad_error_frame,   ///< an error frame written as remote or CAN FD (the kernel makes neither)
  bad_fd_flags,      ///< "##" not followed by one hex digit of flags
  fd_length,         ///< a CAN FD length that is not 0..8, 12, 16, 20, 24, 32, 48 or 64
  bad_data,          ///< a character that is not a hex digit
  odd_data,          ///< an odd number of hex digits
  data_too_long,     ///< more than 8 bytes (classic) or 64 (FD)
  bad_remote,        ///< "R" followed by something other than one length digit 0..8
  bad_raw_dlc,       ///< "_X" not after 8 bytes, or X not 9..F
  trailing_text,     ///< anything after the frame other than " T" or " R"
};

struct ParseError {
  ParseErrorKind kind = ParseErrorKind::empty_line;
  std::string message;  ///< e.g. "bad identifier '02G': expected 3 hex digits ..."
};

/// Parses a frame field ("ID#DATA" and the other forms above) into `frame`.
std::optional<ParseError> parse_frame(std::string_view token, LogFrame& frame);

/// The frame field as candump writes it (upper-case hex). Values out of range are clipped to
/// what the field can say: the identifier to 11/29 bits, the length to 8 or 64, an FD length
/// up to the next valid one (its padding bytes are written as they are in `data`).
std::string format_frame(const LogFrame& frame);

/// The frame as the drive's bus carries it: a classic data frame with an 11-bit identifier.
/// nullopt for every other frame (remote, FD, error, 29-bit identifier).
std::optional<hal::CanFrame> classic_frame(const LogFrame& frame) noexcept;

/// A hal::CanFrame as a log frame (the identifier masked to 11 bits, the length to 8).
LogFrame log_frame(const hal::CanFrame& frame) noexcept;

/// A CAN FD length: 0..8, 12, 16, 20, 24, 32, 48 or 64 bytes.
bool is_fd_length(std::size_t bytes) noexcept;

/// Quotes text for an error message: non-printable bytes as \xNN, long text shortened.
std::string quote(std::string_view text);

}  // namespace imd::can_log
