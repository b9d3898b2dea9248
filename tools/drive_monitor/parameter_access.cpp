#include "tools/drive_monitor/parameter_access.hpp"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "firmware/protocol/frame_codec.hpp"

namespace imd::monitor {

namespace protocol = firmware::protocol;

std::optional<uint8_t> field_named(std::string_view name) {
  for (const protocol::ValueName& v : protocol::kMotorFieldValues) {
    if (name == v.name) return static_cast<uint8_t>(v.raw);
  }
  return std::nullopt;
}

std::string field_names() {
  std::string names;
  for (const protocol::ValueName& v : protocol::kMotorFieldValues) {
    names += (names.empty() ? "" : ", ") + std::string(v.name);
  }
  return names;
}

std::string field_name(uint8_t field) {
  for (const protocol::ValueName& v : protocol::kMotorFieldValues) {
    if (v.raw == field) return v.name;
  }
  return "field " + std::to_string(field);
}

std::string status_name(firmware::ParameterStatus status) {
  for (const protocol::ValueName& v : protocol::kParameterStatusValues) {
    if (v.raw == static_cast<int>(status)) return v.name;
  }
  return "status " + std::to_string(static_cast<int>(status));
}

std::optional<Assignment> parse_assignment(const std::string& text, std::string& error) {
  const auto equals = text.find('=');
  if (equals == std::string::npos) {
    error = "'" + text + "': expected KEY=VALUE, e.g. Rr_Ohm=10.1";
    return std::nullopt;
  }
  const std::string key = text.substr(0, equals), number = text.substr(equals + 1);
  const auto field = field_named(key);
  if (!field) {
    error = "'" + key + "' is not a motor parameter (known: " + field_names() + ")";
    return std::nullopt;
  }
  char* end = nullptr;
  const double value = std::strtod(number.c_str(), &end);
  if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(value) ||
      std::abs(value) > 3e38) {
    error = key + ": '" + number + "' is not a finite number";
    return std::nullopt;
  }
  return Assignment{*field, static_cast<float>(value)};
}

protocol::Command parameter_command(protocol::ParameterOp op, uint8_t field, float value) {
  protocol::Command c;
  c.kind = protocol::CommandKind::parameter_access;
  c.op = op;
  c.field = field;
  c.value = value;
  return c;
}

std::optional<ParameterReply> decode_parameter_value(const hal::CanFrame& frame, uint8_t node_id) {
  const protocol::Message& m = protocol::message(protocol::MessageId::parameter_value);
  if (frame.id != protocol::can_id(node_id, m.id) || frame.length != m.length) return std::nullopt;
  const auto& s = m.signals;
  return ParameterReply{static_cast<uint8_t>(protocol::get_raw(frame.data, s[0])),
                        static_cast<protocol::ParameterOp>(protocol::get_raw(frame.data, s[1])),
                        static_cast<firmware::ParameterStatus>(protocol::get_raw(frame.data, s[2])),
                        protocol::get_physical(frame.data, s[3]),
                        protocol::get_raw(frame.data, s[4]) != 0,
                        protocol::get_raw(frame.data, s[5]) != 0};
}

std::optional<IdentifyProgress> decode_identify_progress(const hal::CanFrame& frame,
                                                         uint8_t node_id) {
  const protocol::Message& m = protocol::message(protocol::MessageId::identify_progress);
  if (frame.id != protocol::can_id(node_id, m.id) || frame.length != m.length) return std::nullopt;
  const auto& s = m.signals;
  return IdentifyProgress{static_cast<uint8_t>(protocol::get_raw(frame.data, s[0])),
                          static_cast<uint8_t>(protocol::get_raw(frame.data, s[2])),
                          protocol::get_physical(frame.data, s[1]),
                          protocol::get_physical(frame.data, s[3])};
}

std::optional<firmware::DriveState> heartbeat_state(const hal::CanFrame& frame, uint8_t node_id) {
  const protocol::Message& m = protocol::message(protocol::MessageId::heartbeat);
  if (frame.id != protocol::can_id(node_id, m.id) || frame.length != m.length) return std::nullopt;
  return static_cast<firmware::DriveState>(protocol::get_raw(frame.data, m.signals[0]));
}

std::string progress_text(const IdentifyProgress& p) {
  const auto& s = protocol::message(protocol::MessageId::identify_progress).signals;
  const char* step = protocol::value_name(s[0], p.step);
  const std::string name = step != nullptr ? step : "step " + std::to_string(p.step);
  const std::string seconds = fmt::format(" ({:.1f} s)", p.seconds);
  if (p.step == 5 || (p.step == 4 && p.failure != 0)) {
    const char* why = protocol::value_name(s[2], p.failure);
    return name + ": " + (why != nullptr ? why : std::to_string(p.failure)) + seconds;
  }
  if (p.ended()) return name + seconds;
  return fmt::format("{} {:.0f} %{}", name, 100.0f * p.fraction, seconds);
}

}  // namespace imd::monitor
