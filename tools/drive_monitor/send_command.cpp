#include "tools/drive_monitor/send_command.hpp"

#include <cmath>
#include <cstdlib>

#include "firmware/protocol/frame_codec.hpp"
#include "tools/drive_monitor/monitor.hpp"

namespace imd::monitor {
namespace {

using protocol::CommandKind;
using protocol::MessageId;

struct CommandWord {
  const char* word;
  CommandKind kind;
  const char* value_name;  ///< nullptr: takes no value
};
constexpr CommandWord kWords[] = {
    {"enable", CommandKind::enable, nullptr},
    {"disable", CommandKind::disable, nullptr},
    {"estop", CommandKind::emergency_stop, nullptr},
    {"clear-faults", CommandKind::clear_faults, nullptr},
    {"set-speed", CommandKind::set_speed, "RAD_S"},
    {"set-flux", CommandKind::set_flux, "WB2"},
    {"select-controller", CommandKind::select_controller, "LAW"},  // a name of kControllerValues
    {"set-telemetry-rate", CommandKind::set_telemetry_rate, "HZ"},
};

/// The value signal of a command's message (after crc and counter).
const protocol::Signal& payload_signal(CommandKind kind) {
  return protocol::message(protocol::message_for(kind)).signals[2];
}

std::string physical_text(const protocol::Signal& s, double value) {
  const std::string text = format_physical(s, value);
  return *s.unit != '\0' ? text + " " + s.unit : text;
}

/// A finite number covering the whole text, or nullopt.
std::optional<double> parse_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<float> parse_value(const CommandWord& w, const std::string& text,
                                 std::string& error) {
  const protocol::Signal& s = payload_signal(w.kind);
  const std::string prefix = std::string(w.word) + ": ";
  if (w.kind == CommandKind::select_controller) {
    std::string known;
    for (const protocol::ValueName& v : s.values) {
      if (text == v.name) return float(v.raw);
      known += (known.empty() ? "" : ", ") + std::string(v.name);
    }
    error = prefix + "unknown controller '" + text + "' (known: " + known + ")";
    return std::nullopt;
  }
  const std::optional<double> number = parse_number(text);
  if (!number) {
    error = prefix + "'" + text + "' is not a number";
    return std::nullopt;
  }
  // Range first in double precision: a double beyond float's range must not be converted.
  const double raw = std::round((*number - s.offset) / s.scale());
  const bool fits = raw >= double(s.raw_min()) && raw <= double(s.raw_max());
  const float value = fits ? static_cast<float>(*number) : 0.0f;
  if (!fits || !protocol::in_range(s, value)) {
    error = prefix + text + " cannot be represented: " + s.name + " spans " +
            physical_text(s, double(s.raw_min()) * s.scale() + s.offset) + " .. " +
            physical_text(s, double(s.raw_max()) * s.scale() + s.offset);
    return std::nullopt;
  }
  if (w.kind == CommandKind::set_flux && !(value > 0.0f)) {
    error = prefix + text + " must be > 0 " + s.unit;
    return std::nullopt;
  }
  if (w.kind == CommandKind::set_telemetry_rate) {
    if (value != std::round(value) || value < float(protocol::kFastTelemetryMinHz) ||
        value > float(protocol::kFastTelemetryMaxHz)) {
      error = prefix + text + " must be a whole number of Hz in " +
              std::to_string(protocol::kFastTelemetryMinHz) + ".." +
              std::to_string(protocol::kFastTelemetryMaxHz);
      return std::nullopt;
    }
  }
  return value;
}

}  // namespace

std::string command_usage() {
  std::string usage;
  for (const CommandWord& w : kWords) {
    if (!usage.empty()) usage += ", ";
    usage += w.word;
    if (w.kind == CommandKind::select_controller) {
      std::string laws;  // the protocol's names, as the DBC has them
      for (const protocol::ValueName& v : protocol::kControllerValues) {
        laws += (laws.empty() ? "" : "|") + std::string(v.name);
      }
      usage += " " + laws;
    } else if (w.value_name != nullptr) {
      usage += std::string(" ") + w.value_name;
    }
  }
  return usage;
}

std::optional<protocol::Command> parse_command(const std::string& name,
                                               const std::optional<std::string>& value,
                                               std::string& error) {
  for (const CommandWord& w : kWords) {
    if (name != w.word) continue;
    if (w.value_name == nullptr) {
      if (value) {
        error = name + " takes no value, got '" + *value + "'";
        return std::nullopt;
      }
      return protocol::Command{w.kind, 0.0f};
    }
    if (!value) {
      error = name + " needs a value (" + w.value_name + ")";
      return std::nullopt;
    }
    const std::optional<float> parsed = parse_value(w, *value, error);
    if (!parsed) return std::nullopt;
    return protocol::Command{w.kind, *parsed};
  }
  error = "unknown command '" + name + "' (known: " + command_usage() + ")";
  return std::nullopt;
}

std::string describe_command(const protocol::Command& command) {
  const protocol::Message& m = protocol::message(protocol::message_for(command.kind));
  if (m.signals.size() <= 2) return m.name;
  // The value as the frame carries it, after rounding to the signal's resolution.
  const protocol::Signal& s = m.signals[2];
  const int64_t raw = protocol::to_raw(s, command.value);
  if (const char* name = protocol::value_name(s, raw)) return std::string(m.name) + " " + name;
  return std::string(m.name) + " " + physical_text(s, double(raw) * s.scale() + s.offset);
}

std::optional<uint8_t> heartbeat_command_counter(const hal::CanFrame& frame, uint8_t node_id) {
  const DecodedFrame d = decode_frame(frame, node_id);
  if (d.kind != FrameKind::decoded || d.message->id != MessageId::heartbeat) return std::nullopt;
  const int index = protocol::find_signal(*d.message, "command_counter");
  return static_cast<uint8_t>(d.signals[std::size_t(index)].raw);
}

std::optional<AckFrame> decode_ack(const hal::CanFrame& frame, uint8_t node_id) {
  const DecodedFrame d = decode_frame(frame, node_id);
  if (d.kind != FrameKind::decoded || d.message->id != MessageId::command_ack) return std::nullopt;
  const auto raw = [&d](const char* name) {
    return d.signals[std::size_t(protocol::find_signal(*d.message, name))].raw;
  };
  return AckFrame{static_cast<uint8_t>(raw("message")), static_cast<uint8_t>(raw("counter")),
                  Ack{static_cast<protocol::CommandResult>(raw("result")),
                      static_cast<uint16_t>(raw("rejected_total"))}};
}

std::optional<Ack> match_ack(const hal::CanFrame& frame, uint8_t node_id, uint8_t message_id,
                             uint8_t counter) {
  const std::optional<AckFrame> a = decode_ack(frame, node_id);
  if (!a || a->message_id != message_id || a->counter != counter) return std::nullopt;
  return a->ack;
}

std::string result_name(protocol::CommandResult result) {
  const protocol::Message& ack = protocol::message(MessageId::command_ack);
  return enum_text(ack.signals[std::size_t(protocol::find_signal(ack, "result"))], int64_t(result));
}

}  // namespace imd::monitor
