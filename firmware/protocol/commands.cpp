#include "firmware/protocol/commands.hpp"

#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/runtime_messages.hpp"

namespace imd::firmware::protocol {
namespace {

/// A raw value of the protocol's controller table (the laws the drive registers).
bool names_a_law(float value) noexcept {
  for (const ValueName& v : kControllerValues) {
    if (value == static_cast<float>(v.raw)) return true;
  }
  return false;
}

constexpr const Signal& payload_signal(MessageId id) noexcept {
  return runtime_message(id).signals[2];
}

}  // namespace

MessageId message_for(CommandKind kind) noexcept {
  switch (kind) {
    case CommandKind::emergency_stop:
      return MessageId::emergency_stop;
    case CommandKind::disable:
      return MessageId::disable;
    case CommandKind::enable:
      return MessageId::enable;
    case CommandKind::clear_faults:
      return MessageId::clear_faults;
    case CommandKind::set_speed:
      return MessageId::set_speed;
    case CommandKind::set_flux:
      return MessageId::set_flux;
    case CommandKind::select_controller:
      return MessageId::select_controller;
    case CommandKind::set_telemetry_rate:
      return MessageId::set_telemetry_rate;
    case CommandKind::parameter_access:
      return MessageId::parameter_access;
    case CommandKind::identify:
      return MessageId::identify;
  }
  return MessageId::disable;
}

Decoded CommandDecoder::reject(Decoded d, CommandResult reason) noexcept {
  d.result = reason;
  ++rejections_[int(reason)];
  ++rejected_total_;
  return d;
}

Decoded CommandDecoder::decode(const hal::CanFrame& frame) noexcept {
  Decoded d;
  if (frame.id > 0x7FF || node_of(frame.id) != node_id_) return d;
  d.message_id = message_of(frame.id);
  const Message* m = find_runtime_message(d.message_id);
  if (m == nullptr || m->direction != Direction::host_to_drive) {
    // The drive's own telemetry echoed on the bus is not a command; an unknown id is.
    if (m != nullptr) return d;
    d.for_this_node = true;
    return reject(d, CommandResult::unknown_message);
  }
  d.for_this_node = true;
  if (frame.length != m->length) return reject(d, CommandResult::wrong_length);
  d.counter = e2e_counter(frame.data);
  if (frame.data[0] != e2e_crc(frame.id, frame.data, frame.length)) {
    return reject(d, CommandResult::bad_crc);
  }
  // The emergency stop is obeyed whatever its counter: stopping twice is harmless, and a host
  // whose counter went out of step must still be able to stop the motor.
  if (have_counter_ && m->id != MessageId::emergency_stop) {
    const uint8_t step = static_cast<uint8_t>((d.counter - last_counter_) & 0x0F);
    if (step == 0) return reject(d, CommandResult::repeated_counter);
    if (step > kMaxCounterStep) return reject(d, CommandResult::stale_counter);
  }
  // The frame passed the E2E checks: its counter is the new reference, as the host's counter
  // moved on, even if the value below is refused.
  have_counter_ = true;
  last_counter_ = d.counter;
  Command& c = d.command;
  switch (m->id) {
    case MessageId::emergency_stop:
      c.kind = CommandKind::emergency_stop;
      break;
    case MessageId::disable:
      c.kind = CommandKind::disable;
      break;
    case MessageId::enable:
      c.kind = CommandKind::enable;
      break;
    case MessageId::clear_faults:
      c.kind = CommandKind::clear_faults;
      break;
    case MessageId::identify:
      c.kind = CommandKind::identify;
      c.value = get_physical(frame.data, payload_signal(MessageId::identify));
      if (c.value != 0.0f && c.value != 1.0f) return reject(d, CommandResult::out_of_range);
      break;
    case MessageId::set_speed:
      c.kind = CommandKind::set_speed;
      c.value = get_physical(frame.data, payload_signal(MessageId::set_speed));
      if (!(c.value >= -limits_.max_speed_rad_s && c.value <= limits_.max_speed_rad_s)) {
        return reject(d, CommandResult::out_of_range);
      }
      break;
    case MessageId::set_flux:
      c.kind = CommandKind::set_flux;
      c.value = get_physical(frame.data, payload_signal(MessageId::set_flux));
      if (!(c.value >= limits_.min_flux2_Wb2 && c.value <= limits_.max_flux2_Wb2)) {
        return reject(d, CommandResult::out_of_range);
      }
      break;
    case MessageId::select_controller:
      c.kind = CommandKind::select_controller;
      c.value = get_physical(frame.data, payload_signal(MessageId::select_controller));
      if (!names_a_law(c.value)) return reject(d, CommandResult::out_of_range);
      break;
    case MessageId::set_telemetry_rate:
      c.kind = CommandKind::set_telemetry_rate;
      c.value = get_physical(frame.data, payload_signal(MessageId::set_telemetry_rate));
      if (!(c.value >= float(kFastTelemetryMinHz) && c.value <= float(kFastTelemetryMaxHz))) {
        return reject(d, CommandResult::out_of_range);
      }
      break;
    case MessageId::parameter_access: {
      // The field and the value are the application's to judge (it answers with a reason);
      // an operation the protocol does not define is a malformed frame.
      const Message& pa = runtime_message(MessageId::parameter_access);
      c.kind = CommandKind::parameter_access;
      const int64_t op = get_raw(frame.data, pa.signals[2]);
      if (op >= kParameterOpCount) return reject(d, CommandResult::out_of_range);
      c.op = static_cast<ParameterOp>(op);
      c.field = static_cast<uint8_t>(get_raw(frame.data, pa.signals[3]));
      c.value = get_physical(frame.data, pa.signals[4]);
      d.result = CommandResult::accepted;
      return d;
    }
    default:
      return reject(d, CommandResult::unknown_message);
  }
  // Reserved bits must be zero, so that a future field is never misread as this one.
  if ((frame.data[1] & 0xF0) != 0) return reject(d, CommandResult::out_of_range);
  d.result = CommandResult::accepted;
  return d;
}

hal::CanFrame CommandEncoder::encode(const Command& command) noexcept {
  const MessageId id = message_for(command.kind);
  const Message& m = runtime_message(id);
  hal::CanFrame frame;
  frame.id = can_id(node_id_, id);
  frame.length = m.length;
  if (id == MessageId::parameter_access) {
    set_raw(frame.data, m.signals[2], static_cast<int64_t>(command.op));
    set_raw(frame.data, m.signals[3], command.field);
    set_physical(frame.data, m.signals[4], command.value);
  } else if (m.signals.size() > 2) {
    set_physical(frame.data, m.signals[2], command.value);
  }
  e2e_protect(frame.id, frame.data, frame.length, counter_);
  counter_ = static_cast<uint8_t>((counter_ + 1) & 0x0F);
  return frame;
}

}  // namespace imd::firmware::protocol
