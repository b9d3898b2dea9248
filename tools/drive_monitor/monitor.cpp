#include "tools/drive_monitor/monitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "firmware/protocol/frame_codec.hpp"

namespace imd::monitor {
namespace {

using protocol::MessageId;

/// The index of a signal by name; a typo fails to compile (the throw is not a constant).
constexpr std::size_t index_of(MessageId id, const char* name) {
  const int index = protocol::find_signal(protocol::message(id), name);
  if (index < 0) throw std::logic_error("no such signal in the protocol table");
  return static_cast<std::size_t>(index);
}

using protocol::signal_of;

namespace heartbeat {
constexpr std::size_t kState = index_of(MessageId::heartbeat, "state");
constexpr std::size_t kFirstFault = index_of(MessageId::heartbeat, "first_fault");
constexpr std::size_t kCounter = index_of(MessageId::heartbeat, "counter");
constexpr std::size_t kCommandCounter = index_of(MessageId::heartbeat, "command_counter");
constexpr std::size_t kController = index_of(MessageId::heartbeat, "controller");
constexpr std::size_t kBusOff = index_of(MessageId::heartbeat, "can_bus_off");
constexpr std::size_t kRejected = index_of(MessageId::heartbeat, "rejected_commands");
constexpr std::size_t kLimited = index_of(MessageId::heartbeat, "limited");
constexpr std::size_t kTransitions = index_of(MessageId::heartbeat, "transitions");
constexpr std::size_t kStop = index_of(MessageId::heartbeat, "stop");
constexpr std::size_t kBrake = index_of(MessageId::heartbeat, "brake");
constexpr std::size_t kResetCause = index_of(MessageId::heartbeat, "reset_cause");
}  // namespace heartbeat

namespace fault_report {
constexpr std::size_t kFirstFault = index_of(MessageId::fault_report, "first_fault");
constexpr std::size_t kTime = index_of(MessageId::fault_report, "first_fault_time_ms");
constexpr std::size_t kDetail = index_of(MessageId::fault_report, "detail");
}  // namespace fault_report

namespace version {
constexpr std::size_t kProtocol = index_of(MessageId::version, "protocol_version");
constexpr std::size_t kMajor = index_of(MessageId::version, "firmware_major");
constexpr std::size_t kMinor = index_of(MessageId::version, "firmware_minor");
constexpr std::size_t kPatch = index_of(MessageId::version, "firmware_patch");
constexpr std::size_t kDirty = index_of(MessageId::version, "dirty");
constexpr std::size_t kGitHash = index_of(MessageId::version, "git_hash");
}  // namespace version

namespace ack {
constexpr std::size_t kMessage = index_of(MessageId::command_ack, "message");
constexpr std::size_t kCounter = index_of(MessageId::command_ack, "counter");
constexpr std::size_t kResult = index_of(MessageId::command_ack, "result");
constexpr std::size_t kRejectedTotal = index_of(MessageId::command_ack, "rejected_total");
}  // namespace ack

namespace state_change {
constexpr std::size_t kFrom = index_of(MessageId::state_change, "from");
constexpr std::size_t kTo = index_of(MessageId::state_change, "to");
constexpr std::size_t kReason = index_of(MessageId::state_change, "reason");
constexpr std::size_t kTransitions = index_of(MessageId::state_change, "transitions");
constexpr std::size_t kTime = index_of(MessageId::state_change, "time_ms");
}  // namespace state_change

namespace timing {
constexpr std::size_t kMean = index_of(MessageId::timing, "exec_mean_us");
constexpr std::size_t kMax = index_of(MessageId::timing, "exec_max_us");
constexpr std::size_t kOverruns = index_of(MessageId::timing, "overruns");
constexpr std::size_t kBudget = index_of(MessageId::timing, "budget_us");
}  // namespace timing

namespace telemetry {
constexpr std::size_t kSpeed = index_of(MessageId::telemetry_speed_flux, "speed_rad_s");
constexpr std::size_t kSpeedRef = index_of(MessageId::telemetry_speed_flux, "speed_ref_rad_s");
constexpr std::size_t kFlux2 = index_of(MessageId::telemetry_speed_flux, "flux2_Wb2");
constexpr std::size_t kFlux2Ref = index_of(MessageId::telemetry_speed_flux, "flux2_ref_Wb2");
constexpr std::size_t kIA = index_of(MessageId::telemetry_current, "iA_A");
constexpr std::size_t kIB = index_of(MessageId::telemetry_current, "iB_A");
constexpr std::size_t kLoad = index_of(MessageId::telemetry_current, "load_Nm");
constexpr std::size_t kVBus = index_of(MessageId::telemetry_current, "v_bus_V");
constexpr std::size_t kUAlpha = index_of(MessageId::telemetry_voltage, "u_alpha_V");
constexpr std::size_t kUBeta = index_of(MessageId::telemetry_voltage, "u_beta_V");
constexpr std::size_t kSample = index_of(MessageId::telemetry_voltage, "sample");
constexpr std::size_t kRrScale = index_of(MessageId::telemetry_voltage, "rr_scale");
}  // namespace telemetry

/// The CSV's telemetry columns, in order; their names are the signals' names.
constexpr const protocol::Signal* kColumns[] = {
    &signal_of(MessageId::telemetry_speed_flux, "speed_rad_s"),
    &signal_of(MessageId::telemetry_speed_flux, "speed_ref_rad_s"),
    &signal_of(MessageId::telemetry_speed_flux, "flux2_Wb2"),
    &signal_of(MessageId::telemetry_speed_flux, "flux2_ref_Wb2"),
    &signal_of(MessageId::telemetry_current, "iA_A"),
    &signal_of(MessageId::telemetry_current, "iB_A"),
    &signal_of(MessageId::telemetry_current, "load_Nm"),
    &signal_of(MessageId::telemetry_current, "v_bus_V"),
    &signal_of(MessageId::telemetry_voltage, "u_alpha_V"),
    &signal_of(MessageId::telemetry_voltage, "u_beta_V"),
    &signal_of(MessageId::telemetry_voltage, "rr_scale"),
};
constexpr const protocol::Signal& kStateSignal = signal_of(MessageId::heartbeat, "state");
constexpr const protocol::Signal& kFirstFaultSignal =
    signal_of(MessageId::heartbeat, "first_fault");

/// Decimal places of a power-of-ten scale (1/100 -> 2), or -1 for another scale.
int scale_decimals(const protocol::Signal& s) noexcept {
  if (s.offset != std::round(s.offset)) return -1;
  if (s.scale_den == 1 && s.scale_num >= 1) return 0;
  if (s.scale_num != 1) return -1;
  int decimals = 0;
  for (int64_t den = s.scale_den; den > 1; den /= 10) {
    if (den % 10 != 0) return -1;
    ++decimals;
  }
  return decimals;
}

}  // namespace

DecodedFrame decode_frame(const hal::CanFrame& frame, uint8_t node_id) {
  DecodedFrame d;
  d.node_id = protocol::node_of(frame.id);
  d.message_id = protocol::message_of(frame.id);
  if (frame.id > 0x7FF || d.node_id != node_id) {
    d.kind = FrameKind::other_node;
    return d;
  }
  d.message = protocol::find_message(d.message_id);
  if (d.message == nullptr) {
    d.kind = FrameKind::unknown_message;
    return d;
  }
  if (frame.length != d.message->length) {
    d.kind = FrameKind::wrong_length;
    return d;
  }
  d.kind = FrameKind::decoded;
  for (const protocol::Signal& s : d.message->signals) {
    SignalValue& v = d.signals[d.signal_count++];
    v.signal = &s;
    v.raw = protocol::get_raw(frame.data, s);
    v.value = protocol::decode_signal(frame, s);
    v.value_name = protocol::value_name(s, v.raw);
  }
  return d;
}

std::string format_physical(const protocol::Signal& signal, double value) {
  char text[64];
  const int decimals = scale_decimals(signal);
  if (decimals >= 0) {
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
  } else {
    std::snprintf(text, sizeof text, "%.9g", value);
  }
  return text;
}

std::string enum_text(const protocol::Signal& signal, int64_t raw) {
  const char* name = protocol::value_name(signal, raw);
  return name != nullptr ? std::string(name) : std::to_string(raw);
}

std::string fault_bit_names(int64_t fault_bits) {
  std::string text;
  for (int bit = 0; bit < 63; ++bit) {
    if (((fault_bits >> bit) & 1) == 0) continue;
    if (!text.empty()) text += ',';
    text += enum_text(kFirstFaultSignal, bit);
  }
  return text.empty() ? "none" : text;
}

std::string describe(const DecodedFrame& frame) {
  char head[64];
  switch (frame.kind) {
    case FrameKind::other_node:
      std::snprintf(head, sizeof head, "node %d message 0x%02X (not watched)", frame.node_id,
                    frame.message_id);
      return head;
    case FrameKind::unknown_message:
      std::snprintf(head, sizeof head, "unknown message 0x%02X", frame.message_id);
      return head;
    case FrameKind::wrong_length:
      return std::string(frame.message->name) + " (wrong length, expected " +
             std::to_string(frame.message->length) + ")";
    case FrameKind::decoded:
      break;
  }
  std::string text = frame.message->name;
  int64_t fault_bits = -1;  // the fault bits, one word: "faults=overcurrent,encoder"
  for (std::size_t i = 0; i < frame.signal_count; ++i) {
    const SignalValue& v = frame.signals[i];
    if (const int code = protocol::fault_code_of(*v.signal); code > 0) {
      fault_bits = std::max<int64_t>(fault_bits, 0) | (v.raw << code);
      continue;
    }
    text += ' ';
    text += v.signal->name;
    text += '=';
    text +=
        v.value_name != nullptr ? std::string(v.value_name) : format_physical(*v.signal, v.value);
  }
  if (fault_bits >= 0) text += " faults=" + fault_bit_names(fault_bits);
  return text;
}

std::string csv_header() {
  std::string header = "time_s";
  for (const protocol::Signal* s : kColumns) header += std::string(",") + s->name;
  return header + ",sample,state,first_fault";
}

std::string csv_row(const TelemetryRow& row) {
  const double values[] = {
      row.speed_rad_s, row.speed_ref_rad_s, row.flux2_Wb2, row.flux2_ref_Wb2, row.iA_A,
      row.iB_A,        row.load_Nm,         row.v_bus_V,   row.u_alpha_V,     row.u_beta_V,
      row.rr_scale};
  static_assert(std::size(values) == std::size(kColumns));
  char time[32];
  std::snprintf(time, sizeof time, "%.6f", row.time_s);
  std::string line = time;
  for (std::size_t i = 0; i < std::size(values); ++i) {
    line += ',';
    line += format_physical(*kColumns[i], values[i]);
  }
  return line + ',' + std::to_string(row.sample) + ',' + row.state + ',' + row.first_fault;
}

std::optional<TelemetryRow> DriveMonitor::feed(double time_s, const hal::CanFrame& frame) {
  FrameCounts& counts = status_.frames;
  ++counts.total;
  status_.last_time_s = time_s;
  const DecodedFrame d = decode_frame(frame, node_id_);
  switch (d.kind) {
    case FrameKind::other_node:
      ++counts.other_nodes;
      if (d.node_id < counts.other_node_frames.size()) ++counts.other_node_frames[d.node_id];
      return std::nullopt;
    case FrameKind::unknown_message:
      ++counts.unknown;
      return std::nullopt;
    case FrameKind::wrong_length:
      ++counts.wrong_length;
      return std::nullopt;
    case FrameKind::decoded:
      ++counts.decoded;
      break;
  }
  if (d.message->direction == protocol::Direction::host_to_drive) {
    ++counts.commands;
    return std::nullopt;
  }
  const auto raw = [&d](std::size_t index) { return d.signals[index].raw; };
  const auto value = [&d](std::size_t index) { return d.signals[index].value; };
  switch (d.message->id) {
    case MessageId::heartbeat: {
      HeartbeatStatus& h = status_.heartbeat;
      ++h.count;
      h.time_s = time_s;
      h.state = raw(heartbeat::kState);
      h.fault_bits = protocol::get_fault_bits(frame.data, protocol::kHeartbeatFaultWordBit);
      h.first_fault = raw(heartbeat::kFirstFault);
      h.counter = raw(heartbeat::kCounter);
      h.command_counter = raw(heartbeat::kCommandCounter);
      h.controller = raw(heartbeat::kController);
      h.can_bus_off = raw(heartbeat::kBusOff) != 0;
      h.rejected_commands = raw(heartbeat::kRejected);
      h.limited = raw(heartbeat::kLimited);
      h.transitions = raw(heartbeat::kTransitions);
      h.stop = raw(heartbeat::kStop);
      h.brake = raw(heartbeat::kBrake) != 0;
      h.reset_cause = raw(heartbeat::kResetCause);
      break;
    }
    case MessageId::fault_report: {
      FaultReportStatus& f = status_.fault_report;
      ++f.count;
      f.first_fault = raw(fault_report::kFirstFault);
      f.fault_bits = protocol::get_fault_bits(frame.data, protocol::kFaultReportFaultWordBit);
      f.first_fault_time_ms = raw(fault_report::kTime);
      f.detail = raw(fault_report::kDetail);
      break;
    }
    case MessageId::version: {
      VersionStatus& v = status_.version;
      ++v.count;
      v.protocol_version = raw(version::kProtocol);
      v.major = raw(version::kMajor);
      v.minor = raw(version::kMinor);
      v.patch = raw(version::kPatch);
      v.dirty = raw(version::kDirty) != 0;
      v.git_hash = static_cast<uint32_t>(raw(version::kGitHash));
      break;
    }
    case MessageId::command_ack: {
      AckStatus& a = status_.ack;
      ++a.count;
      a.time_s = time_s;
      a.message_id = raw(ack::kMessage);
      a.counter = raw(ack::kCounter);
      a.result = raw(ack::kResult);
      a.rejected_total = raw(ack::kRejectedTotal);
      break;
    }
    case MessageId::state_change: {
      StateChangeStatus& s = status_.state_change;
      ++s.count;
      s.from = raw(state_change::kFrom);
      s.to = raw(state_change::kTo);
      s.reason = raw(state_change::kReason);
      s.transitions = raw(state_change::kTransitions);
      s.time_ms = raw(state_change::kTime);
      break;
    }
    case MessageId::timing: {
      TimingStatus& t = status_.timing;
      ++t.count;
      t.exec_mean_us = value(timing::kMean);
      t.exec_max_us = value(timing::kMax);
      t.overruns = raw(timing::kOverruns);
      t.budget_us = value(timing::kBudget);
      break;
    }
    case MessageId::telemetry_speed_flux:
      speed_flux_ = d;
      speed_flux_fresh_ = true;
      break;
    case MessageId::telemetry_current:
      current_ = d;
      current_fresh_ = true;
      break;
    case MessageId::telemetry_voltage:
      return on_voltage(time_s, d);
    default:
      break;
  }
  return std::nullopt;
}

std::optional<TelemetryRow> DriveMonitor::on_voltage(double time_s, const DecodedFrame& d) {
  if (!speed_flux_ || !current_) {
    ++status_.frames.incomplete_samples;
    return std::nullopt;
  }
  if (!speed_flux_fresh_ || !current_fresh_) ++status_.frames.stale_samples;
  speed_flux_fresh_ = current_fresh_ = false;

  TelemetryRow row;
  row.time_s = time_s;
  const DecodedFrame& sf = *speed_flux_;
  const DecodedFrame& cu = *current_;
  row.speed_rad_s = sf.signals[telemetry::kSpeed].value;
  row.speed_ref_rad_s = sf.signals[telemetry::kSpeedRef].value;
  row.flux2_Wb2 = sf.signals[telemetry::kFlux2].value;
  row.flux2_ref_Wb2 = sf.signals[telemetry::kFlux2Ref].value;
  row.iA_A = cu.signals[telemetry::kIA].value;
  row.iB_A = cu.signals[telemetry::kIB].value;
  row.load_Nm = cu.signals[telemetry::kLoad].value;
  row.v_bus_V = cu.signals[telemetry::kVBus].value;
  row.u_alpha_V = d.signals[telemetry::kUAlpha].value;
  row.u_beta_V = d.signals[telemetry::kUBeta].value;
  row.sample = static_cast<int>(d.signals[telemetry::kSample].raw);
  row.rr_scale = d.signals[telemetry::kRrScale].value;
  const HeartbeatStatus& h = status_.heartbeat;
  if (h.count > 0) {
    row.state = enum_text(kStateSignal, h.state);
    row.first_fault = enum_text(kFirstFaultSignal, h.first_fault);
  }
  ++status_.frames.rows;
  status_.last_row = row;
  return row;
}

}  // namespace imd::monitor
