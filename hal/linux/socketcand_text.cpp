#include "hal/linux/socketcand_text.hpp"

#include <array>
#include <cctype>
#include <cstdio>
#include <vector>

namespace imd::hal {
namespace {

constexpr std::size_t kQuoted_chars = 24;      // how much of a bad text an error repeats
constexpr std::size_t kMaxBusName_chars = 16;  // socketcand's limit

bool is_space(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

/// The text as an error quotes it: trimmed, cut to kQuoted_chars.
std::string quoted(std::string_view text) {
  text = trim(text);
  std::string out = "'";
  out.append(text.substr(0, kQuoted_chars));
  return out.append(text.size() > kQuoted_chars ? "...'" : "'");
}

std::vector<std::string_view> split_words(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_space(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !is_space(text[i])) ++i;
    if (i > start) words.push_back(text.substr(start, i - start));
  }
  return words;
}

/// Parses 1..`max_digits` hex digits; false for anything else.
bool parse_hex(std::string_view word, std::size_t max_digits, uint32_t& value) {
  if (word.empty() || word.size() > max_digits) return false;
  value = 0;
  for (const char c : word) {
    const int digit = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                      : (c >= 'a' && c <= 'f')                    ? c - 'a' + 10
                      : (c >= 'A' && c <= 'F')                    ? c - 'A' + 10
                                                                  : -1;
    if (digit < 0) return false;
    value = value * 16 + static_cast<uint32_t>(digit);
  }
  return true;
}

SocketcandCommand bad(SocketcandCommand::Kind kind, std::string why) {
  SocketcandCommand c;
  c.kind = kind;
  c.error = std::move(why);
  return c;
}

SocketcandCommand parse_send(const std::vector<std::string_view>& w) {
  using Kind = SocketcandCommand::Kind;
  if (w.size() < 3) return bad(Kind::bad, "send needs ID LEN [BYTE]..., e.g. send 21 1 5");
  uint32_t id = 0;
  if (w[1].size() == 8 && parse_hex(w[1], 8, id)) {
    return bad(Kind::bad, "send " + std::string(w[1]) +
                              ": 29-bit identifier; the drive uses 11-bit identifiers only");
  }
  if (!parse_hex(w[1], 7, id))
    return bad(Kind::bad, "send: identifier " + quoted(w[1]) + " is not hex");
  if (id > 0x7FF) return bad(Kind::bad, "send: identifier " + std::string(w[1]) + " above 7FF");
  if (w[2].size() != 1 || w[2][0] < '0' || w[2][0] > '8') {
    return bad(Kind::bad,
               "send " + std::string(w[1]) + ": length " + quoted(w[2]) + " is not 0..8");
  }
  const std::size_t length = static_cast<std::size_t>(w[2][0] - '0');
  if (w.size() - 3 != length) {
    return bad(Kind::bad, "send " + std::string(w[1]) + ": length " + std::to_string(length) +
                              " but " + std::to_string(w.size() - 3) + " data bytes");
  }
  SocketcandCommand c;
  c.kind = Kind::send;
  c.frame.id = static_cast<uint16_t>(id);
  c.frame.length = static_cast<uint8_t>(length);
  for (std::size_t i = 0; i < length; ++i) {
    uint32_t byte = 0;
    if (!parse_hex(w[3 + i], 2, byte)) {
      return bad(Kind::bad, "send " + std::string(w[1]) + ": data byte " + std::to_string(i) + " " +
                                quoted(w[3 + i]) + " is not 1 or 2 hex digits");
    }
    c.frame.data[i] = static_cast<uint8_t>(byte);
  }
  return c;
}

}  // namespace

void SocketcandReader::feed(std::string_view bytes) {
  buffer_.append(bytes);
}

std::optional<SocketcandPiece> SocketcandReader::next() {
  std::size_t start = 0;
  while (start < buffer_.size() && is_space(buffer_[start])) ++start;
  buffer_.erase(0, start);
  if (buffer_.empty()) return std::nullopt;
  if (buffer_[0] != '<') {
    const std::size_t open = buffer_.find('<');
    const std::size_t end = open == std::string::npos ? buffer_.size() : open;
    SocketcandPiece piece{
        "text outside a message: " + quoted(std::string_view(buffer_).substr(0, end)), true};
    buffer_.erase(0, end);
    return piece;
  }
  const std::size_t end = buffer_.find_first_of("<>", 1);
  if (end != std::string::npos && buffer_[end] == '>') {
    SocketcandPiece piece{std::string(trim(std::string_view(buffer_).substr(1, end - 1))), false};
    buffer_.erase(0, end + 1);
    return piece;
  }
  if (end != std::string::npos) {  // a '<' before the '>'
    SocketcandPiece piece{"message not closed: " + quoted(std::string_view(buffer_).substr(0, end)),
                          true};
    buffer_.erase(0, end);
    return piece;
  }
  if (buffer_.size() > kMaxMessage_chars) {
    SocketcandPiece piece{"message longer than " + std::to_string(kMaxMessage_chars) +
                              " characters: " + quoted(buffer_),
                          true};
    // Its rest, up to the next '<', is then reported once as text outside < >.
    buffer_.clear();
    return piece;
  }
  return std::nullopt;  // the message's end is still on its way
}

SocketcandCommand parse_socketcand(std::string_view words) {
  using Kind = SocketcandCommand::Kind;
  const std::vector<std::string_view> w = split_words(words);
  if (w.empty()) return bad(Kind::bad, "empty message");
  const std::string_view verb = w[0];
  const std::string name(verb);
  if (verb == "send") return parse_send(w);
  if (verb == "open") {
    if (w.size() != 2 || w[1].size() > kMaxBusName_chars) {
      return bad(Kind::bad, "open needs one bus name of at most 16 characters, e.g. open can0");
    }
    SocketcandCommand c;
    c.kind = Kind::open;
    c.channel = std::string(w[1]);
    return c;
  }
  const Kind plain = verb == "rawmode"   ? Kind::rawmode
                     : verb == "bcmmode" ? Kind::bcmmode
                     : verb == "echo"    ? Kind::echo
                                         : Kind::bad;
  if (plain != Kind::bad) {
    if (w.size() != 1) return bad(Kind::bad, name + " takes no arguments");
    SocketcandCommand c;
    c.kind = plain;
    return c;
  }
  static constexpr std::array<std::string_view, 11> kNotServed = {
      "add",         "update",      "delete",     "filter",    "muxfilter", "subscribe",
      "unsubscribe", "controlmode", "statistics", "isotpmode", "isotpconf"};
  for (const std::string_view other : kNotServed) {
    if (verb == other) {
      return bad(Kind::unsupported, name +
                                        " is not served: this server has raw mode only "
                                        "(rawmode, send, echo)");
    }
  }
  return bad(Kind::bad, "unknown command " + quoted(verb));
}

std::string format_socketcand_frame(const CanFrame& frame, int64_t seconds, int64_t micros) {
  const std::size_t length = frame.length <= 8 ? frame.length : 8;
  char text[80];
  int n = std::snprintf(text, sizeof text, "< frame %03X %lld.%06lld ", frame.id & 0x7FFu,
                        static_cast<long long>(seconds), static_cast<long long>(micros));
  for (std::size_t i = 0; i < length; ++i) {
    n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), "%02X", frame.data[i]);
  }
  std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), " >");
  return text;
}

SocketcandReply parse_socketcand_reply(std::string_view words) {
  using Kind = SocketcandReply::Kind;
  const std::vector<std::string_view> w = split_words(words);
  SocketcandReply r;
  if (w.size() == 1 && (w[0] == "ok" || w[0] == "hi" || w[0] == "echo")) {
    r.kind = w[0] == "ok" ? Kind::ok : w[0] == "hi" ? Kind::hi : Kind::echo;
    return r;
  }
  if (!w.empty() && w[0] == "error") {
    r.kind = Kind::error;
    r.text = std::string(trim(words.substr(words.find("error") + 5)));
    return r;
  }
  if (w.empty() || w[0] != "frame") {
    r.kind = Kind::other;
    r.text = "unexpected message " + quoted(words);
    return r;
  }
  r.kind = Kind::bad;
  uint32_t id = 0;
  // socketcand documents `< frame 123 23.424242 11 22 33 44 >` (a word per byte) and writes
  // the data as one word; both are read: the data words are joined. Each word holds whole
  // bytes, so that `1 2` is refused rather than read as 0x12.
  std::string data;
  bool whole_bytes = true;
  for (std::size_t i = 3; i < w.size(); ++i) {
    data.append(w[i]);
    whole_bytes = whole_bytes && w[i].size() % 2 == 0;
  }
  if (w.size() < 3) {
    r.text = "frame needs ID TIME [DATA]: " + quoted(words);
  } else if (w[1].size() == 8 && parse_hex(w[1], 8, id)) {
    r.kind = Kind::other;
    r.text = "29-bit frame " + std::string(w[1]) + " skipped: the drive uses 11-bit identifiers";
  } else if (!parse_hex(w[1], 3, id) || id > 0x7FF) {
    r.text = "frame: identifier " + quoted(w[1]) + " is not 11-bit hex";
  } else if (!whole_bytes || data.size() > 16) {
    r.text = "frame " + std::string(w[1]) + ": data " + quoted(data) + " is not 0..8 hex bytes";
  } else {
    r.frame.id = static_cast<uint16_t>(id);
    r.frame.length = static_cast<uint8_t>(data.size() / 2);
    for (std::size_t i = 0; i < r.frame.length; ++i) {
      uint32_t byte = 0;
      if (!parse_hex(std::string_view(data).substr(2 * i, 2), 2, byte)) {
        r.text = "frame " + std::string(w[1]) + ": data " + quoted(data) + " is not hex";
        return r;
      }
      r.frame.data[i] = static_cast<uint8_t>(byte);
    }
    r.kind = Kind::frame;
  }
  return r;
}

std::string format_socketcand_send(const CanFrame& frame) {
  const std::size_t length = frame.length <= 8 ? frame.length : 8;
  char text[64];
  int n = std::snprintf(text, sizeof text, "< send %03X %zu", frame.id & 0x7FFu, length);
  for (std::size_t i = 0; i < length; ++i) {
    n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), " %02X", frame.data[i]);
  }
  std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), " >");
  return text;
}

std::string format_socketcand_error(std::string_view text) {
  std::string out = "< error ";
  for (const char c : text) out += (c == '<' || c == '>') ? '?' : c;
  out += " >";
  return out;
}

}  // namespace imd::hal
