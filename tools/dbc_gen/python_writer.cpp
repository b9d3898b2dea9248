// The protocol table as a Python module (tools/python/imdrive/protocol_table.py): plain data,
// no logic, so that the Python client reads the same table the firmware and the DBC file come
// from. The client builds its codec from these literals.
#include <imd_version.hpp>
#include <fmt/format.h>

#include <charconv>
#include <cstdlib>
#include <iterator>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "firmware/protocol/commands.hpp"
#include "protocol_text.hpp"
#include "writers.hpp"

namespace imd::tools::dbc {
namespace {

namespace protocol = firmware::protocol;
using Out = std::back_insert_iterator<std::string>;

/// A Python string literal: double quotes, with backslash escapes for anything not plain ASCII
/// (the table's texts are DBC-safe already; this keeps the module valid if that ever changes).
std::string py_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u >= 0x7F) {
      out += fmt::format("\\x{:02x}", u);
    } else {
      out += c;
    }
  }
  return out + "\"";
}

/// A Python float literal that reads back as `value` (shortest round trip, always with a '.' or
/// an exponent so that Python sees a float).
std::string py_float(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

/// A single-precision table value as the decimal the table wrote (0.01f is 0.01).
double decimal(float value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer - 1, value);
  *result.ptr = '\0';
  return std::strtod(buffer, nullptr);
}

const char* py_bool(bool value) {
  return value ? "True" : "False";
}

const char* direction_name(protocol::Direction d) {
  return d == protocol::Direction::host_to_drive ? "host_to_drive" : "drive_to_host";
}

const char* timing_name(protocol::Timing t) {
  switch (t) {
    case protocol::Timing::cyclic:
      return "cyclic";
    case protocol::Timing::configurable:
      return "configurable";
    case protocol::Timing::on_event:
      return "on_event";
  }
  return "on_event";
}

/// The distinct value tables, each named after the first signal that uses it
/// (STATE_VALUES), or after its message and signal when that name is taken.
struct ValueTable {
  std::string name;
  std::span<const protocol::ValueName> values;
};

bool same_values(std::span<const protocol::ValueName> a, std::span<const protocol::ValueName> b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].raw != b[i].raw || std::string_view(a[i].name) != b[i].name) return false;
  }
  return true;
}

std::string upper(std::string_view text) {
  std::string out;
  for (const char c : text) out += (c >= 'a' && c <= 'z') ? char(c - 'a' + 'A') : c;
  return out;
}

std::vector<ValueTable> value_tables() {
  std::vector<ValueTable> tables;
  for (const protocol::Message& m : protocol::kMessages) {
    for (const protocol::Signal& s : m.signals) {
      if (s.values.empty()) continue;
      bool known = false, name_taken = false;
      for (const ValueTable& t : tables) {
        known = known || same_values(t.values, s.values);
        name_taken = name_taken || t.name == upper(s.name) + "_VALUES";
      }
      if (known) continue;
      const std::string stem = name_taken ? std::string(m.name) + "_" + s.name : s.name;
      tables.push_back({upper(stem) + "_VALUES", s.values});
    }
  }
  return tables;
}

const std::string& table_name(const std::vector<ValueTable>& tables, const protocol::Signal& s) {
  for (const ValueTable& t : tables) {
    if (same_values(t.values, s.values)) return t.name;
  }
  static const std::string kNone = "()";
  return kNone;
}

void write_value_table(Out out, const ValueTable& t) {
  std::string line = t.name + " = (";
  for (const protocol::ValueName& v : t.values) {
    const std::string item = fmt::format("({}, {}),", v.raw, py_string(v.name));
    if (line.size() + item.size() + 1 > 99) {
      fmt::format_to(out, "{}\n", line);
      line = "   ";
    }
    line += (line.back() == '(' ? "" : " ") + item;
  }
  fmt::format_to(out, "{})\n", line);
}

void write_signal(Out out, const protocol::Signal& s, const std::vector<ValueTable>& tables) {
  std::string minimum = "None", maximum = "None";
  // The physical range the drive accepts when the table gives one, else the range the bits
  // can carry (a float signal: any float, None).
  if (s.has_range) {
    minimum = py_float(decimal(s.range_min));
    maximum = py_float(decimal(s.range_max));
  } else if (!s.is_float) {
    minimum = py_float(physical(s, s.raw_min()));
    maximum = py_float(physical(s, s.raw_max()));
  }
  fmt::format_to(out,
                 "        Signal({}, start_bit={}, length_bits={}, is_signed={}, scale_num={},\n"
                 "               scale_den={}, offset={}, unit={}, minimum={}, maximum={},\n"
                 "               is_float={}, values={},\n"
                 "               comment={}),\n",
                 py_string(s.name), s.start_bit, s.length_bits, py_bool(s.is_signed), s.scale_num,
                 s.scale_den, py_float(decimal_offset(s)), py_string(s.unit), minimum, maximum,
                 py_bool(s.is_float), s.values.empty() ? "()" : table_name(tables, s),
                 py_string(s.comment));
}

void write_message(Out out, const protocol::Message& m, const std::vector<ValueTable>& tables) {
  fmt::format_to(out, "    Message(0x{:02X}, {}, length={}, direction={}, timing={}, period_ms={},\n",
                 static_cast<unsigned>(m.id), py_string(m.name), m.length,
                 py_string(direction_name(m.direction)), py_string(timing_name(m.timing)),
                 m.period_ms);
  fmt::format_to(out, "            comment={},\n", py_string(m.comment));
  fmt::format_to(out, "            signals=(\n");
  for (const protocol::Signal& s : m.signals) write_signal(out, s, tables);
  fmt::format_to(out, "    )),\n");
}

}  // namespace

std::string python_text() {
  std::string text;
  const Out out = std::back_inserter(text);
  fmt::format_to(out,
                 "# Generated by dbc_gen --python from firmware/protocol/messages.hpp: do not "
                 "edit.\n"
                 "# Generated data, exempt from the 400-line limit: the whole table in one "
                 "module.\n"
                 "# Regenerate: build/bin/dbc_gen --python tools/python/imdrive/protocol_table.py\n"
                 "\"\"\"The drive's CAN protocol table as data; imdrive.table builds the codec "
                 "from it.\"\"\"\n"
                 "from collections import namedtuple\n\n");
  fmt::format_to(out, "# The project version this table belongs to (CMakeLists.txt).\n");
  fmt::format_to(out, "PROJECT_VERSION = \"{}.{}.{}\"\n\n", imd::version::kMajor,
                 imd::version::kMinor, imd::version::kPatch);
  fmt::format_to(out, "# The layout of the table on the wire (the version frame carries it).\n");
  fmt::format_to(out, "PROTOCOL_VERSION = {}\n", protocol::kProtocolVersion);
  fmt::format_to(out, "NOMINAL_BITRATE_BIT_S = {}\n", protocol::kNominalBitrate_bit_s);
  fmt::format_to(out, "MAX_NODE_ID = {}\n", protocol::kMaxNodeId);
  fmt::format_to(out, "# can_id = node_id * NODE_STRIDE + message id\n");
  fmt::format_to(out, "NODE_STRIDE = {}\n", protocol::can_id(1, protocol::MessageId{0}));
  fmt::format_to(out, "FAST_TELEMETRY_MIN_HZ = {}\n", protocol::kFastTelemetryMinHz);
  fmt::format_to(out, "FAST_TELEMETRY_MAX_HZ = {}\n", protocol::kFastTelemetryMaxHz);
  fmt::format_to(out, "# A command's alive counter may run this far ahead of the last one.\n");
  fmt::format_to(out, "MAX_COUNTER_STEP = {}\n\n", protocol::kMaxCounterStep);
  fmt::format_to(out,
                 "Signal = namedtuple(\"Signal\", \"name start_bit length_bits is_signed "
                 "scale_num scale_den offset unit minimum maximum is_float comment values\")\n"
                 "Message = namedtuple(\"Message\", \"id name length direction timing period_ms "
                 "comment signals\")\n\n");
  const std::vector<ValueTable> tables = value_tables();
  fmt::format_to(out, "# Value names of the enumerated signals: (raw, name) pairs.\n");
  for (const ValueTable& t : tables) write_value_table(out, t);
  fmt::format_to(out, "\nMESSAGES = (\n");
  for (const protocol::Message& m : protocol::kMessages) write_message(out, m, tables);
  fmt::format_to(out, ")\n");
  return text;
}

}  // namespace imd::tools::dbc
