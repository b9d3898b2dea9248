#include "tools/can_log/candump_log.hpp"

#include <cmath>
#include <cstdio>

namespace imd::can_log {
namespace {

constexpr std::size_t kMaxSecondsDigits = 12;  // up to ~31700 years: no overflow in microseconds
constexpr std::size_t kMicrosDigits = 6;
constexpr std::size_t kNanosDigits = 9;          // candump -N
constexpr std::size_t kMaxInterfaceLength = 15;  // IFNAMSIZ - 1: also candump's widest padding

bool all_digits(std::string_view text) noexcept {
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return !text.empty();
}

int64_t decimal_value(std::string_view digits) noexcept {
  int64_t value = 0;
  for (const char c : digits) value = value * 10 + (c - '0');
  return value;
}

ParseResult fail(ParseErrorKind kind, std::string message) {
  ParseResult result;
  result.error = ParseError{kind, std::move(message)};
  return result;
}

/// "(SECONDS.MICROS)" or "(SECONDS.NANOS)" -> microseconds (nanoseconds rounded half up), or -1.
int64_t parse_timestamp(std::string_view inner) noexcept {
  const std::size_t dot = inner.find('.');
  if (dot == std::string_view::npos) return -1;
  const std::string_view seconds = inner.substr(0, dot);
  const std::string_view fraction = inner.substr(dot + 1);
  if (!all_digits(seconds) || seconds.size() > kMaxSecondsDigits) return -1;
  if (!all_digits(fraction)) return -1;
  const int64_t whole_us = decimal_value(seconds) * 1'000'000;
  if (fraction.size() == kMicrosDigits) return whole_us + decimal_value(fraction);
  // Rounded in integers, so 0.999999500 carries into the next second exactly.
  if (fraction.size() == kNanosDigits) return whole_us + (decimal_value(fraction) + 500) / 1000;
  return -1;
}

/// The first character of `text` that is a control character, space or non-ASCII, or npos.
std::size_t first_bad_name_char(std::string_view text) noexcept {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c <= 0x20 || c >= 0x7F) return i;
  }
  return std::string_view::npos;
}

/// Removes `prefix` from the front of `text`; false if it is not there.
bool consume(std::string_view& text, std::string_view prefix) noexcept {
  if (text.substr(0, prefix.size()) != prefix) return false;
  text.remove_prefix(prefix.size());
  return true;
}

/// A decimal number of at most 10 digits (candump prints a __u32) from the front of `text`.
std::optional<uint64_t> consume_count(std::string_view& text) noexcept {
  std::size_t digits = 0;
  while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
  if (digits == 0 || digits > 10) return std::nullopt;
  const auto value = static_cast<uint64_t>(decimal_value(text.substr(0, digits)));
  text.remove_prefix(digits);
  return value;
}

constexpr std::string_view kDropcount = "DROPCOUNT:";

}  // namespace

std::optional<uint64_t> parse_dropcount_line(std::string_view text) {
  // candump.c: "DROPCOUNT: dropped %u CAN frame%s on '%s' socket (total drops %u)".
  if (!consume(text, "DROPCOUNT: dropped ")) return std::nullopt;
  const std::optional<uint64_t> dropped = consume_count(text);
  if (!dropped || !consume(text, *dropped > 1 ? " CAN frames on '" : " CAN frame on '")) {
    return std::nullopt;
  }
  // '%s' is candump's argument as given, filters included ("can0,020:7E0,7FF:7FF"), so it is
  // neither bounded to an interface name's length nor free of ',' ':': take it all.
  constexpr std::string_view kSocketTail = "' socket (total drops ";
  const std::size_t tail = text.rfind(kSocketTail);
  if (tail == std::string_view::npos || tail == 0) return std::nullopt;
  text.remove_prefix(tail);
  if (!consume(text, kSocketTail) || !consume_count(text) || text != ")") {
    return std::nullopt;
  }
  return dropped;
}

ParseResult parse_log_line(std::string_view text) {
  if (text.empty()) return fail(ParseErrorKind::empty_line, "empty line");
  // (SECONDS.MICROS)
  const std::size_t close = text.find(')');
  if (text[0] != '(' || close == std::string_view::npos) {
    const std::string_view head = text.substr(0, text.find(' '));
    return fail(ParseErrorKind::bad_timestamp,
                "bad timestamp " + quote(head) + ": expected '(SECONDS.MICROS)' first");
  }
  ParsedLine line;
  line.time_us = parse_timestamp(text.substr(1, close - 1));
  if (line.time_us < 0) {
    return fail(ParseErrorKind::bad_timestamp,
                "bad timestamp " + quote(text.substr(0, close + 1)) +
                    ": expected '(SECONDS.MICROS)' with 6 or 9 decimals");
  }
  line.time_s = double(line.time_us) * 1e-6;

  // One space, the interface (right-aligned by candump when it has several), one space, the
  // frame.
  std::string_view rest = text.substr(close + 1);
  if (rest.empty()) {
    return fail(ParseErrorKind::missing_field, "missing interface and frame after the timestamp");
  }
  if (rest[0] != ' ') {
    return fail(ParseErrorKind::bad_separator,
                "expected one space after the timestamp, got " + quote(rest.substr(0, 2)));
  }
  rest.remove_prefix(1);
  const std::size_t padding = rest.find_first_not_of(' ');
  if (padding == std::string_view::npos) {
    return fail(ParseErrorKind::missing_field, "missing interface and frame after the timestamp");
  }
  rest.remove_prefix(padding);
  const std::size_t space = rest.find(' ');
  const std::string_view iface = rest.substr(0, space);
  if (space == std::string_view::npos) {
    return fail(ParseErrorKind::missing_field, "missing frame after interface " + quote(iface));
  }
  if (first_bad_name_char(iface) != std::string_view::npos) {
    return fail(ParseErrorKind::bad_interface,
                "bad interface name " + quote(iface) + ": control or non-ASCII character");
  }
  if (iface.size() > kMaxInterfaceLength) {
    return fail(ParseErrorKind::bad_interface,
                "bad interface name " + quote(iface) + ": longer than 15 characters");
  }
  if (padding + iface.size() > kMaxInterfaceLength) {
    return fail(ParseErrorKind::bad_separator, std::to_string(padding + 1) +
                                                   " spaces before interface " + quote(iface) +
                                                   ": candump pads names to at most 15 characters");
  }
  line.iface = std::string(iface);
  rest.remove_prefix(space + 1);
  if (rest.empty()) {
    return fail(ParseErrorKind::missing_field, "missing frame after interface " + quote(iface));
  }
  if (rest[0] == ' ') {
    return fail(ParseErrorKind::bad_separator,
                "expected one space after interface " + quote(iface) + ", got several");
  }
  const std::size_t end = rest.find(' ');
  if (auto error = parse_frame(rest.substr(0, end), line.frame)) {
    return fail(error->kind, error->message);
  }
  const std::string_view trailing =
      end == std::string_view::npos ? std::string_view{} : rest.substr(end);
  if (trailing == " T") {
    line.direction = Direction::transmitted;
  } else if (trailing == " R") {
    line.direction = Direction::received;
  } else if (!trailing.empty()) {
    return fail(ParseErrorKind::trailing_text,
                "unexpected text after the frame: " + quote(trailing) +
                    " (only ' T' or ' R' may follow, as candump -x writes)");
  }
  ParseResult result;
  result.line = std::move(line);
  return result;
}

std::string format_log_line(double time_s, std::string_view iface, const LogFrame& frame,
                            Direction direction) {
  constexpr double kMaxTime_s = 999'999'999'999.0;
  int64_t time_us = 0;
  if (std::isfinite(time_s) && time_s > 0.0) {
    time_us = std::llround((time_s < kMaxTime_s ? time_s : kMaxTime_s) * 1e6);
  }
  char head[48];
  std::snprintf(head, sizeof head, "(%lld.%06lld) ", static_cast<long long>(time_us / 1'000'000),
                static_cast<long long>(time_us % 1'000'000));
  std::string out = head;
  out += iface;
  out += ' ';
  out += format_frame(frame);
  if (direction == Direction::transmitted) out += " T";
  if (direction == Direction::received) out += " R";
  return out;
}

std::string format_log_line(double time_s, std::string_view iface, const hal::CanFrame& frame,
                            Direction direction) {
  return format_log_line(time_s, iface, log_frame(frame), direction);
}

LogReader::LogReader(const std::string& path) : path_(path), stream_(path) {
  if (!stream_.is_open()) error_ = path + ": cannot open file";
}

bool LogReader::next(ParsedLine& line) {
  if (!error_.empty() || !stream_.is_open()) return false;
  std::string text;
  while (std::getline(stream_, text)) {
    ++line_number_;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.empty()) continue;
    if (std::string_view(text).substr(0, kDropcount.size()) == kDropcount) {
      const std::optional<uint64_t> dropped = parse_dropcount_line(text);
      if (!dropped) {
        error_ = path_ + ":" + std::to_string(line_number_) + ": bad DROPCOUNT line " +
                 quote(text) +
                 ": expected \"DROPCOUNT: dropped N CAN frames on 'IFACE' socket (total drops "
                 "M)\"";
        return false;
      }
      dropped_frames_ += *dropped;
      continue;
    }
    ParseResult result = parse_log_line(text);
    if (!result.ok()) {
      error_ = path_ + ":" + std::to_string(line_number_) + ": " + result.error.message;
      return false;
    }
    line = std::move(*result.line);
    return true;
  }
  if (stream_.bad()) error_ = path_ + ": read error";
  return false;
}

LogWriter::LogWriter(const std::string& path, std::string iface)
    : stream_(path, std::ios::out | std::ios::trunc), iface_(std::move(iface)) {
  if (!stream_.is_open()) error_ = path + ": cannot open file for writing";
}

void LogWriter::write(double time_s, const hal::CanFrame& frame, Direction direction) {
  stream_ << format_log_line(time_s, iface_, frame, direction) << '\n';
}

}  // namespace imd::can_log
