#include "tools/can_log/candump_frame.hpp"

#include <cstdio>

namespace imd::can_log {
namespace {

constexpr std::size_t kMaxQuoted = 48;
constexpr uint32_t kMaxStandardId = 0x7FF;
constexpr uint32_t kMaxExtendedId = 0x1FFFFFFF;
constexpr uint32_t kMaxErrorId = kErrorFlag | kMaxExtendedId;
constexpr std::size_t kClassicBytes = 8;
constexpr std::size_t kFdBytes = 64;
constexpr char kHex[] = "0123456789ABCDEF";

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

ParseError error(ParseErrorKind kind, std::string message) {
  return ParseError{kind, std::move(message)};
}

/// Hex pairs into frame.data, at most `max_bytes`; `what` names the frame kind in messages.
std::optional<ParseError> parse_bytes(std::string_view text, std::size_t max_bytes,
                                      const char* what, LogFrame& frame) {
  for (const char c : text) {
    if (hex_value(c) < 0) {
      return error(ParseErrorKind::bad_data, "bad data " + quote(text) + ": " +
                                                 quote(std::string_view(&c, 1)) +
                                                 " is not a hex digit");
    }
  }
  if (text.size() > 2 * max_bytes) {
    return error(ParseErrorKind::data_too_long,
                 "data " + quote(text) + " has " + std::to_string((text.size() + 1) / 2) +
                     " bytes: " + what + " carries at most " + std::to_string(max_bytes));
  }
  if (text.size() % 2 != 0) {
    return error(ParseErrorKind::odd_data,
                 "data " + quote(text) + " has an odd number of hex digits (" +
                     std::to_string(text.size()) + "): expected whole bytes");
  }
  frame.length = static_cast<uint8_t>(text.size() / 2);
  for (std::size_t i = 0; i < frame.length; ++i) {
    frame.data[i] = static_cast<uint8_t>(hex_value(text[2 * i]) * 16 + hex_value(text[2 * i + 1]));
  }
  return std::nullopt;
}

/// "_X" after 8 bytes: the raw DLC 9..F a classic controller may send with 8 data bytes.
std::optional<ParseError> parse_raw_dlc(std::string_view suffix, LogFrame& frame) {
  const int dlc = suffix.size() == 2 ? hex_value(suffix[1]) : -1;
  if (frame.length != kClassicBytes || dlc < 9) {
    return error(ParseErrorKind::bad_raw_dlc,
                 "bad raw DLC " + quote(suffix) +
                     ": expected '_' and one digit 9..F, after exactly 8 data bytes");
  }
  frame.raw_dlc = static_cast<uint8_t>(dlc);
  return std::nullopt;
}

std::optional<ParseError> parse_remote(std::string_view text, LogFrame& frame) {
  frame.type = FrameType::remote;
  const std::string_view rest = text.substr(1);
  if (rest.empty()) return std::nullopt;
  if (rest[0] < '0' || rest[0] > '8' || (rest.size() > 1 && rest[1] != '_')) {
    return error(ParseErrorKind::bad_remote,
                 "bad remote frame " + quote(text) +
                     ": expected 'R' or 'R' followed by one length digit 0..8");
  }
  frame.length = static_cast<uint8_t>(rest[0] - '0');
  return rest.size() > 1 ? parse_raw_dlc(rest.substr(1), frame) : std::nullopt;
}

std::optional<ParseError> parse_fd(std::string_view text, LogFrame& frame) {
  frame.type = FrameType::fd;
  if (text.size() < 2 || hex_value(text[1]) < 0) {
    return error(ParseErrorKind::bad_fd_flags, "bad CAN FD frame " +
                                                   quote("#" + std::string(text)) +
                                                   ": expected one hex digit of flags after '##'");
  }
  frame.fd_flags = static_cast<uint8_t>(hex_value(text[1]));
  if (auto e = parse_bytes(text.substr(2), kFdBytes, "CAN FD", frame)) return e;
  if (!is_fd_length(frame.length)) {
    return error(ParseErrorKind::fd_length,
                 "CAN FD data " + quote(text.substr(2)) + " has " + std::to_string(frame.length) +
                     " bytes: a CAN FD frame carries 0..8, 12, 16, 20, 24, 32, 48 or 64");
  }
  return std::nullopt;
}

std::optional<ParseError> parse_classic(std::string_view text, LogFrame& frame) {
  const std::size_t underscore = text.find('_');
  if (auto e = parse_bytes(text.substr(0, underscore), kClassicBytes, "classic CAN", frame)) {
    return e;
  }
  if (underscore == std::string_view::npos) return std::nullopt;
  return parse_raw_dlc(text.substr(underscore), frame);
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

bool is_fd_length(std::size_t bytes) noexcept {
  switch (bytes) {
    case 12:
    case 16:
    case 20:
    case 24:
    case 32:
    case 48:
    case 64:
      return true;
    default:
      return bytes <= kClassicBytes;
  }
}

std::optional<ParseError> parse_frame(std::string_view token, LogFrame& frame) {
  frame = LogFrame{};
  const std::size_t hash = token.find('#');
  if (hash == std::string_view::npos) {
    return error(ParseErrorKind::missing_hash,
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
    return error(ParseErrorKind::bad_identifier,
                 "bad identifier " + quote(id_text) +
                     ": expected 3 hex digits (or 8 for an extended identifier or error frame)");
  }
  const bool long_id = id_text.size() == 8;
  if (!long_id && id > kMaxStandardId) {
    return error(ParseErrorKind::identifier_range,
                 "identifier " + quote(id_text) + " is above 7FF (11 bits)");
  }
  if (long_id && id > kMaxErrorId) {
    return error(ParseErrorKind::identifier_range,
                 "identifier " + quote(id_text) +
                     " is above 1FFFFFFF (29 bits), and above 3FFFFFFF for an error frame");
  }
  const bool is_error = long_id && (id & kErrorFlag) != 0;
  const std::string_view rest = token.substr(hash + 1);
  const bool fd = !rest.empty() && rest[0] == '#';
  const bool remote = !rest.empty() && rest[0] == 'R';
  if (is_error && (fd || remote)) {
    return error(ParseErrorKind::bad_error_frame,
                 "error frame " + quote(token) +
                     (fd ? " written as CAN FD ('##')" : " written as remote ('R')") +
                     ": error frames are classic data frames");
  }
  std::optional<ParseError> e = fd       ? parse_fd(rest, frame)
                                : remote ? parse_remote(rest, frame)
                                         : parse_classic(rest, frame);
  if (e) return e;
  if (is_error) frame.type = FrameType::error;
  frame.extended = long_id && !is_error;
  frame.id = is_error ? id & kMaxExtendedId : id;
  return std::nullopt;
}

std::string format_frame(const LogFrame& frame) {
  char id[16];
  if (frame.type == FrameType::error) {
    std::snprintf(id, sizeof id, "%08X#", unsigned((frame.id & kMaxExtendedId) | kErrorFlag));
  } else if (frame.extended) {
    std::snprintf(id, sizeof id, "%08X#", unsigned(frame.id & kMaxExtendedId));
  } else {
    std::snprintf(id, sizeof id, "%03X#", unsigned(frame.id & kMaxStandardId));
  }
  std::string out = id;
  const bool raw_dlc = frame.raw_dlc >= 9 && frame.raw_dlc <= 15;
  if (frame.type == FrameType::remote) {
    const std::size_t length = frame.length < kClassicBytes ? frame.length : kClassicBytes;
    out += 'R';
    if (length > 0) out += kHex[length];
    if (length == kClassicBytes && raw_dlc) (out += '_') += kHex[frame.raw_dlc];
    return out;
  }
  std::size_t length = frame.length;
  if (frame.type == FrameType::fd) {
    (out += '#') += kHex[frame.fd_flags & 0x0F];
    if (length > kFdBytes) length = kFdBytes;
    while (!is_fd_length(length)) ++length;
  } else if (length > kClassicBytes) {
    length = kClassicBytes;
  }
  for (std::size_t i = 0; i < length; ++i) {
    out += kHex[frame.data[i] >> 4];
    out += kHex[frame.data[i] & 0x0F];
  }
  if (frame.type != FrameType::fd && length == kClassicBytes && raw_dlc) {
    (out += '_') += kHex[frame.raw_dlc];
  }
  return out;
}

std::optional<hal::CanFrame> classic_frame(const LogFrame& frame) noexcept {
  if (frame.type != FrameType::data || frame.extended) return std::nullopt;
  hal::CanFrame out;
  out.id = static_cast<uint16_t>(frame.id & kMaxStandardId);
  out.length = frame.length < kClassicBytes ? frame.length : uint8_t(kClassicBytes);
  for (std::size_t i = 0; i < out.length; ++i) out.data[i] = frame.data[i];
  return out;
}

LogFrame log_frame(const hal::CanFrame& frame) noexcept {
  LogFrame out;
  out.id = frame.id & kMaxStandardId;
  out.length = frame.length < kClassicBytes ? frame.length : uint8_t(kClassicBytes);
  for (std::size_t i = 0; i < out.length; ++i) out.data[i] = frame.data[i];
  return out;
}

}  // namespace imd::can_log
