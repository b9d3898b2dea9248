#pragma once
/// Text shared by the DBC and the Markdown writers: exact numbers, signal ranges and types, and
/// compile-time checks that the message table can be written as a DBC file at all.
#include <string>
#include <string_view>

#include "firmware/protocol/messages.hpp"

namespace imd::tools::dbc {

using firmware::protocol::Message;
using firmware::protocol::Signal;

/// The shortest decimal that reads back as `value`, never in exponent notation: 0.01, 1000,
/// 0.000001, -327.68.
std::string plain_decimal(double value);

/// The physical value of a raw value, rounded once (so 0.01 prints as 0.01, not 0.0099999).
double physical(const Signal& s, int64_t raw);

inline std::string scale_text(const Signal& s) {
  return plain_decimal(s.scale());
}
/// A float of the table as the decimal the table wrote (0.1f is 0.1, not 0.10000000149).
double decimal(float value);
inline double decimal_offset(const Signal& s) {
  return decimal(s.offset);
}
inline std::string offset_text(const Signal& s) {
  return plain_decimal(decimal_offset(s));
}
// The range the drive accepts where the table gives one, else the raw range. A float signal's
// range is the float's: a DBC writes it as [0|0] (no range).
inline std::string min_text(const Signal& s) {
  if (s.has_range) return plain_decimal(decimal(s.range_min));
  return s.is_float ? "0" : plain_decimal(physical(s, s.raw_min()));
}
inline std::string max_text(const Signal& s) {
  if (s.has_range) return plain_decimal(decimal(s.range_max));
  return s.is_float ? "0" : plain_decimal(physical(s, s.raw_max()));
}

/// "uint8", "int16", "uint4", ...
std::string type_name(const Signal& s);

/// "0 calibrating, 1 idle, ..." or "".
std::string value_list(const Signal& s);

/// The two nodes of the DBC file: the drive and the host that commands it.
inline constexpr const char* kDriveNode = "Drive";
inline constexpr const char* kHostNode = "Host";

constexpr const char* transmitter(const Message& m) {
  return m.e2e() ? kHostNode : kDriveNode;
}
constexpr const char* receiver(const Message& m) {
  return m.e2e() ? kDriveNode : kHostNode;
}

/// Whether a message is sent periodically (cyclic, or fast telemetry with a default period).
constexpr bool periodic(const Message& m) {
  return m.timing != firmware::protocol::Timing::on_event;
}

// --- what a DBC file needs of the table, checked when dbc_gen is compiled

constexpr bool is_identifier(std::string_view name) {
  if (name.empty() || name.size() > 32) return false;  // 32: the classic DBC name limit
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    const bool digit = c >= '0' && c <= '9';
    if (!letter && !(digit && i > 0)) return false;
  }
  return true;
}

/// DBC strings are double-quoted and one line long (some parsers read line by line).
constexpr bool is_dbc_string(std::string_view text) {
  for (const char c : text) {
    if (c == '"' || c == '\\' || c == '\n' || c == '\r' || c < ' ' || c > '~') return false;
  }
  return true;
}

constexpr bool signal_is_writable(const Signal& s, int length_bytes) {
  if (!is_identifier(s.name) || !is_dbc_string(s.unit) || !is_dbc_string(s.comment)) return false;
  if (s.length_bits == 0 || s.start_bit + s.length_bits > 8 * length_bytes) return false;
  if (s.scale_num <= 0 || s.scale_den <= 0) return false;
  if (s.is_float && (s.length_bits != 32 || s.is_signed || s.scale() != 1.0 || s.offset != 0.0f ||
                     !s.values.empty())) {
    return false;  // SIG_VALTYPE_ 1: a plain single-precision float
  }
  for (const auto& v : s.values) {
    if (!is_dbc_string(v.name) || v.raw < s.raw_min() || v.raw > s.raw_max()) return false;
  }
  // A range lies within what the raw bits can say (scale > 0: raw_min maps to the lowest).
  const double lowest = double(s.raw_min()) * s.scale() + double(s.offset);
  const double highest = double(s.raw_max()) * s.scale() + double(s.offset);
  if (s.has_range && (s.is_float || !(s.range_min <= s.range_max) || s.range_min < lowest ||
                      s.range_max > highest)) {
    return false;
  }
  return true;
}

/// Unitless whole numbers that count, check or identify rather than name a choice: they need no
/// value table. (detail's meaning depends on the fault: docs/can/protocol.md lists it.)
inline constexpr std::string_view kPlainNumberSignals[] = {
    "crc",            "counter",        "command_counter", "rejected_commands",
    "transitions",    "rejected_total", "sample",          "overruns",
    "detail",         "protocol_version", "firmware_major", "firmware_minor",
    "firmware_patch", "git_hash",
};

/// An enumerated signal (unitless, whole-numbered, wider than a flag, and not a plain number)
/// has a value table, so that tools show names, not numbers.
constexpr bool enumeration_is_named(const Signal& s) {
  const bool whole = !s.is_float && s.scale_num == 1 && s.scale_den == 1 && s.offset == 0.0f;
  if (!whole || *s.unit != '\0' || s.length_bits == 1 || !s.values.empty()) return true;
  for (const std::string_view name : kPlainNumberSignals) {
    if (name == s.name) return true;
  }
  return false;
}
static_assert(!enumeration_is_named(Signal{"mode", 0, 4, false}) &&
                  enumeration_is_named(Signal{"counter", 0, 4, false}) &&
                  enumeration_is_named(Signal{"flag", 0, 1, false}),
              "an unnamed 4-bit mode is an enumeration without a table; counters and flags not");

constexpr uint64_t bit_mask(const Signal& s) {
  return (s.length_bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << s.length_bits) - 1) << s.start_bit;
}

/// Valid names and texts, signals inside their frame, no two sharing a bit or a name.
constexpr bool message_is_writable(const Message& m) {
  // "_63": the suffix a multi-drive file adds must keep the name within the 32-character limit.
  if (!is_identifier(m.name) || std::string_view(m.name).size() + 3 > 32 ||
      !is_dbc_string(m.comment) || m.length > 8) {
    return false;
  }
  if (periodic(m) && m.period_ms == 0) return false;
  uint64_t used_bits = 0;
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const Signal& s = m.signals[i];
    if (!signal_is_writable(s, m.length) || (used_bits & bit_mask(s)) != 0) return false;
    if (!enumeration_is_named(s)) return false;
    used_bits |= bit_mask(s);
    for (std::size_t j = 0; j < i; ++j) {
      if (std::string_view(s.name) == m.signals[j].name) return false;
    }
  }
  return true;
}

/// Every message writable, names and ids unique.
constexpr bool table_is_writable() {
  const auto& messages = firmware::protocol::kMessages;
  for (std::size_t i = 0; i < std::size(messages); ++i) {
    if (!message_is_writable(messages[i]) || uint8_t(messages[i].id) > 31) return false;
    for (std::size_t j = 0; j < i; ++j) {
      if (messages[i].id == messages[j].id) return false;
      if (std::string_view(messages[i].name) == messages[j].name) return false;
    }
  }
  return true;
}
static_assert(
    table_is_writable(),
    "firmware/protocol/messages.hpp: a name, text, bit range or physical range cannot go into a "
    "DBC file, or an enumerated signal has no value table");

}  // namespace imd::tools::dbc
