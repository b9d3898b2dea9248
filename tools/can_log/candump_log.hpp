#pragma once
/// The candump `-L` log format, one frame a line:
///
///     (SECONDS.MICROS) IFACE FRAME[ DIRECTION]
///     (0.000100) can0 022#0103000000000000
///     (1700000000.000250) can0 18FF0001#0102 R
///
/// The fraction has 6 digits, or 9 with candump -N (nanoseconds: rounded half up to the
/// microsecond, so ParsedLine::time_us stays exact for 6 digits and within 0.5 us for 9).
/// FRAME is any frame candump writes (candump_frame.hpp: classic, remote, 29-bit, CAN FD, error
/// frames). DIRECTION, written by candump -x, is T for a frame the capturing host transmitted
/// and R for one it received. With several interfaces candump right-aligns the names, so spaces
/// may pad IFACE on its left up to 15 characters. The writer produces what candump -L produces;
/// the parser is strict and never throws: any other line gives an error that says what is wrong
/// and quotes the offending text.
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

#include "hal/can_bus.hpp"
#include "tools/can_log/candump_frame.hpp"

namespace imd::can_log {

/// Which way a frame went through the capturing interface (candump -x); unmarked without -x.
enum class Direction : uint8_t { unmarked, received, transmitted };

/// A parsed log line.
struct ParsedLine {
  double time_s = 0.0;  ///< the timestamp, seconds
  int64_t time_us = 0;  ///< the same, exact, microseconds
  std::string iface;    ///< the interface name, e.g. "can0" (without its padding)
  LogFrame frame;
  Direction direction = Direction::unmarked;
};

/// Either a line or an error.
struct ParseResult {
  std::optional<ParsedLine> line;
  ParseError error;  ///< meaningful when !ok()

  bool ok() const noexcept { return line.has_value(); }
};

/// Parses one line (without its line terminator). Never throws on malformed input.
ParseResult parse_log_line(std::string_view text);

/// One frame as a candump -L line, without the newline: "(%.6f) IFACE FRAME", then " T" or
/// " R" for a marked direction. A negative or non-finite time is written as 0.
std::string format_log_line(double time_s, std::string_view iface, const LogFrame& frame,
                            Direction direction = Direction::unmarked);
/// The same for a frame of the drive's bus (the identifier masked to 11 bits, the length
/// limited to 8 bytes: a hal::CanFrame carries nothing else).
std::string format_log_line(double time_s, std::string_view iface, const hal::CanFrame& frame,
                            Direction direction = Direction::unmarked);

/// The frames a "DROPCOUNT: dropped N CAN frame(s) on 'ARG' socket (total drops M)" line
/// says were lost (candump -d writes it where the socket dropped frames), or nullopt when the
/// line is not exactly that. ARG is candump's argument as given, filters included
/// ("can0,020:7E0,7FF:7FF"): any non-empty text up to the last "' socket (total drops ".
std::optional<uint64_t> parse_dropcount_line(std::string_view text);

/// Reads a log file line by line. Blank lines are skipped and a trailing '\r' is ignored;
/// DROPCOUNT lines are counted (dropped_frames()); anything else must parse. Errors read
/// "PATH:LINE: message" ("PATH: cannot open file").
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
  /// Frames the capture lost, by its DROPCOUNT lines so far.
  uint64_t dropped_frames() const noexcept { return dropped_frames_; }

 private:
  std::string path_;
  std::ifstream stream_;
  std::string error_;
  long line_number_ = 0;
  uint64_t dropped_frames_ = 0;
};

/// Writes frames to a log file (the simulator's --can-log).
class LogWriter {
 public:
  /// Opens (truncates) `path`; check is_open() and error().
  LogWriter(const std::string& path, std::string iface);

  bool is_open() const noexcept { return stream_.is_open(); }
  const std::string& error() const noexcept { return error_; }
  void write(double time_s, const hal::CanFrame& frame, Direction direction = Direction::unmarked);
  /// False if a write failed (disk full, ...).
  bool good() const noexcept { return stream_.good(); }

 private:
  std::ofstream stream_;
  std::string iface_;
  std::string error_;
};

}  // namespace imd::can_log
