#pragma once
/// The candump `-L` log format, one frame a line:
///
///     (SECONDS.MICROS) IFACE ID#HEXDATA
///     (0.000100) can0 022#0103000000000000
///
/// ID is 3 hex digits (11-bit standard identifier) or 8 (29-bit extended identifier, which the
/// drive's protocol does not use: the parser recognizes it and reports it as unsupported).
/// HEXDATA is 0..8 bytes as pairs of hex digits (`022#` is an empty frame); `R` or `R<len>`
/// instead of the data marks a remote frame. The writer produces what candump -L produces;
/// the parser is strict and never throws: any other line gives an error that says what is wrong
/// and quotes the offending text.
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

#include "hal/can_bus.hpp"

namespace imd::can_log {

/// A parsed log line.
struct ParsedLine {
  double time_s = 0.0;  ///< the timestamp, seconds
  int64_t time_us = 0;  ///< the same, exact, microseconds
  std::string iface;    ///< the interface name, e.g. "can0"
  hal::CanFrame frame;  ///< for a remote frame: the requested length, data all zero
  bool remote = false;  ///< a remote (RTR) frame
};

/// What is wrong with a line (one kind per check, so that tests and tools can tell them apart).
enum class ParseErrorKind : uint8_t {
  empty_line,
  bad_timestamp,        ///< not "(SECONDS.MICROS)" with 6 decimals
  bad_separator,        ///< fields not separated by exactly one space
  missing_field,        ///< the line ends before the interface or the frame
  bad_interface,        ///< empty, too long, or containing control characters
  missing_hash,         ///< no '#' between identifier and data
  bad_identifier,       ///< not 3 or 8 hex digits
  identifier_range,     ///< 3 digits above 7FF, or 8 digits above 1FFFFFFF
  extended_identifier,  ///< a well-formed 29-bit identifier: not supported by the protocol
  can_fd_frame,         ///< "ID##FLAGS DATA": CAN FD, not supported
  bad_data,             ///< a character that is not a hex digit
  odd_data,             ///< an odd number of hex digits
  data_too_long,        ///< more than 8 bytes
  bad_remote,           ///< "R" followed by something other than one length digit 0..8
  trailing_text,        ///< anything after the data
};

struct ParseError {
  ParseErrorKind kind = ParseErrorKind::empty_line;
  std::string message;  ///< e.g. "bad identifier '02G': expected 3 hex digits ..."
};

/// Either a line or an error.
struct ParseResult {
  std::optional<ParsedLine> line;
  ParseError error;  ///< meaningful when !ok()

  bool ok() const noexcept { return line.has_value(); }
};

/// Parses one line (without its line terminator). Never throws on malformed input.
ParseResult parse_log_line(std::string_view text);

/// One frame as a candump -L line, without the newline: "(%.6f) IFACE %03X#HEX". A negative
/// or non-finite time is written as 0; the identifier is masked to 11 bits and the length
/// limited to 8 bytes (a hal::CanFrame carries nothing else).
std::string format_log_line(double time_s, std::string_view iface, const hal::CanFrame& frame);

/// Quotes text for an error message: non-printable bytes as \xNN, long text shortened.
std::string quote(std::string_view text);

/// Reads a log file line by line. Blank lines are skipped and a trailing '\r' is ignored;
/// anything else must parse. Errors read "PATH:LINE: message" ("PATH: cannot open file").
class LogReader {
 public:
  explicit LogReader(const std::string& path);

  /// Whether the file opened (error() says why not).
  bool is_open() const noexcept { return stream_.is_open(); }
  /// The next frame; false at the end of the file or on the first bad line (then error() is
  /// set and the reader stops).
  bool next(ParsedLine& line);
  /// Empty unless the file could not be opened or a line did not parse.
  const std::string& error() const noexcept { return error_; }
  /// The number of the last line read, 1-based.
  long line_number() const noexcept { return line_number_; }

 private:
  std::string path_;
  std::ifstream stream_;
  std::string error_;
  long line_number_ = 0;
};

/// Writes frames to a log file (the simulator's --can-log).
class LogWriter {
 public:
  /// Opens (truncates) `path`; check is_open() and error().
  LogWriter(const std::string& path, std::string iface);

  bool is_open() const noexcept { return stream_.is_open(); }
  const std::string& error() const noexcept { return error_; }
  void write(double time_s, const hal::CanFrame& frame);
  /// False if a write failed (disk full, ...).
  bool good() const noexcept { return stream_.good(); }

 private:
  std::ofstream stream_;
  std::string iface_;
  std::string error_;
};

}  // namespace imd::can_log
