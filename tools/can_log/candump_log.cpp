#include "tools/can_log/candump_log.hpp"

#include <cmath>
#include <cstdio>

namespace imd::can_log {
namespace {

constexpr std::size_t kMaxQuoted = 48;
constexpr std::size_t kMaxSecondsDigits = 12;  // up to ~31700 years: no overflow in microseconds
constexpr std::size_t kMicrosDigits = 6;
constexpr std::size_t kMaxInterfaceLength = 15;  // IFNAMSIZ - 1
constexpr uint32_t kMaxStandardId = 0x7FF;
constexpr uint32_t kMaxExtendedId = 0x1FFFFFFF;

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

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

/// "(SECONDS.MICROS)" -> microseconds, or -1.
int64_t parse_timestamp(std::string_view inner) noexcept {
  const std::size_t dot = inner.find('.');
  if (dot == std::string_view::npos) return -1;
  const std::string_view seconds = inner.substr(0, dot);
  const std::string_view micros = inner.substr(dot + 1);
  if (!all_digits(seconds) || seconds.size() > kMaxSecondsDigits) return -1;
  if (!all_digits(micros) || micros.size() != kMicrosDigits) return -1;
  return decimal_value(seconds) * 1'000'000 + decimal_value(micros);
}

/// The first character of `text` that is a control character, space or non-ASCII, or npos.
std::size_t first_bad_name_char(std::string_view text) noexcept {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c <= 0x20 || c >= 0x7F) return i;
  }
  return std::string_view::npos;
}

/// Parses the data after '#' into `line.frame` (or marks a remote frame).
std::optional<ParseError> parse_data(std::string_view data, ParsedLine& line) {
  if (!data.empty() && data[0] == '#') {
    return ParseError{ParseErrorKind::can_fd_frame,
                      "CAN FD frame " + quote(data) + " ('##'): only classic CAN is supported"};
  }
  if (!data.empty() && data[0] == 'R') {
    line.remote = true;
    const std::string_view rest = data.substr(1);
    if (rest.empty()) return std::nullopt;
    if (rest.size() == 1 && rest[0] >= '0' && rest[0] <= '8') {
      line.frame.length = static_cast<uint8_t>(rest[0] - '0');
      return std::nullopt;
    }
    return ParseError{ParseErrorKind::bad_remote,
                      "bad remote frame " + quote(data) +
                          ": expected 'R' or 'R' followed by one length digit 0..8"};
  }
  for (const char c : data) {
    if (hex_value(c) < 0) {
      return ParseError{ParseErrorKind::bad_data, "bad data " + quote(data) + ": " +
                                                      quote(std::string_view(&c, 1)) +
                                                      " is not a hex digit"};
    }
  }
  if (data.size() > 2 * line.frame.data.size()) {
    return ParseError{ParseErrorKind::data_too_long, "data " + quote(data) + " has " +
                                                         std::to_string((data.size() + 1) / 2) +
                                                         " bytes: classic CAN carries at most 8"};
  }
  if (data.size() % 2 != 0) {
    return ParseError{ParseErrorKind::odd_data,
                      "data " + quote(data) + " has an odd number of hex digits (" +
                          std::to_string(data.size()) + "): expected whole bytes"};
  }
  line.frame.length = static_cast<uint8_t>(data.size() / 2);
  for (std::size_t i = 0; i < line.frame.length; ++i) {
    line.frame.data[i] =
        static_cast<uint8_t>(hex_value(data[2 * i]) * 16 + hex_value(data[2 * i + 1]));
  }
  return std::nullopt;
}

}  // namespace

std::string quote(std::string_view text) {
  std::string out = "'";
  const std::size_t shown = text.size() > kMaxQuoted ? kMaxQuoted : text.size();
  for (std::size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c >= 0x7F || c == '\\') {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", unsigned(c));
      out += escaped;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (shown < text.size()) out += "...";
  return out + "'";
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
    return fail(ParseErrorKind::bad_timestamp, "bad timestamp " + quote(text.substr(0, close + 1)) +
                                                   ": expected '(SECONDS.MICROS)' with 6 decimals");
  }
  line.time_s = double(line.time_us) * 1e-6;

  // One space, the interface, one space, the frame.
  std::string_view rest = text.substr(close + 1);
  if (rest.empty()) {
    return fail(ParseErrorKind::missing_field, "missing interface and frame after the timestamp");
  }
  if (rest[0] != ' ' || (rest.size() > 1 && rest[1] == ' ')) {
    return fail(ParseErrorKind::bad_separator,
                "expected one space after the timestamp, got " + quote(rest.substr(0, 2)));
  }
  rest.remove_prefix(1);
  if (rest.empty()) {
    return fail(ParseErrorKind::missing_field, "missing interface and frame after the timestamp");
  }
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
  const std::string_view token = rest.substr(0, end);
  const std::string_view trailing =
      end == std::string_view::npos ? std::string_view{} : rest.substr(end);

  // ID#DATA
  const std::size_t hash = token.find('#');
  if (hash == std::string_view::npos) {
    return fail(ParseErrorKind::missing_hash,
                "bad frame " + quote(token) + ": expected ID#DATA (no '#' found)");
  }
  const std::string_view id_text = token.substr(0, hash);
  uint32_t id = 0;
  bool hex = !id_text.empty();
  for (const char c : id_text) {
    hex = hex && hex_value(c) >= 0;
    if (hex && id_text.size() <= 8) id = id * 16 + uint32_t(hex_value(c));
  }
  if (!hex || (id_text.size() != 3 && id_text.size() != 8)) {
    return fail(ParseErrorKind::bad_identifier,
                "bad identifier " + quote(id_text) +
                    ": expected 3 hex digits (or 8 for an extended identifier)");
  }
  const bool extended = id_text.size() == 8;
  if (id > (extended ? kMaxExtendedId : kMaxStandardId)) {
    return fail(ParseErrorKind::identifier_range,
                "identifier " + quote(id_text) +
                    (extended ? " is above 1FFFFFFF (29 bits)" : " is above 7FF (11 bits)"));
  }
  if (auto error = parse_data(token.substr(hash + 1), line))
    return fail(error->kind, error->message);
  if (!trailing.empty()) {
    return fail(ParseErrorKind::trailing_text,
                "unexpected text after the frame: " + quote(trailing));
  }
  if (extended) {
    return fail(ParseErrorKind::extended_identifier,
                "extended identifier " + quote(id_text) +
                    " (29 bits): not supported by the protocol (11-bit identifiers only)");
  }
  line.frame.id = static_cast<uint16_t>(id);
  ParseResult result;
  result.line = std::move(line);
  return result;
}

std::string format_log_line(double time_s, std::string_view iface, const hal::CanFrame& frame) {
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
  char id[8];
  std::snprintf(id, sizeof id, " %03X#", unsigned(frame.id & kMaxStandardId));
  out += id;
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::size_t length = frame.length < 8 ? frame.length : 8;
  for (std::size_t i = 0; i < length; ++i) {
    out += kHex[frame.data[i] >> 4];
    out += kHex[frame.data[i] & 0x0F];
  }
  return out;
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

void LogWriter::write(double time_s, const hal::CanFrame& frame) {
  stream_ << format_log_line(time_s, iface_, frame) << '\n';
}

}  // namespace imd::can_log
