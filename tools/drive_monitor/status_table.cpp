#include "tools/drive_monitor/status_table.hpp"

#include <fmt/format.h>

#include "firmware/protocol/frame_codec.hpp"

namespace imd::monitor {
namespace {

using protocol::MessageId;

const protocol::Signal& signal(MessageId id, const char* name) {
  const protocol::Message& m = protocol::message(id);
  return m.signals[static_cast<std::size_t>(protocol::find_signal(m, name))];
}

std::string message_name(int64_t message_id) {
  const protocol::Message* m =
      message_id >= 0 && message_id <= 0xFF ? protocol::find_message(uint8_t(message_id)) : nullptr;
  return m != nullptr ? m->name : fmt::format("message 0x{:02X}", message_id);
}

void add(std::string& out, const char* label, const std::string& text) {
  out += fmt::format("  {:<14} {}\n", label, text);
}

std::string value(MessageId id, const char* name, double physical) {
  const protocol::Signal& s = signal(id, name);
  const std::string text = format_physical(s, physical);
  return *s.unit != '\0' ? text + " " + s.unit : text;
}

void add_heartbeat(std::string& out, const DriveStatus& status) {
  const HeartbeatStatus& h = status.heartbeat;
  if (h.count == 0) {
    add(out, "state", "(no heartbeat yet)");
    return;
  }
  add(out, "state",
      fmt::format("{} (controller {})", enum_text(signal(MessageId::heartbeat, "state"), h.state),
                  enum_text(signal(MessageId::heartbeat, "controller"), h.controller)));
  add(out, "faults",
      fmt::format("bits 0x{:04X} ({}), first {}", h.fault_bits, fault_bit_names(h.fault_bits),
                  enum_text(signal(MessageId::heartbeat, "first_fault"), h.first_fault)));
  add(out, "heartbeat",
      fmt::format("#{} ({} received), command counter {}, drive CAN bus-off {}", h.counter, h.count,
                  h.command_counter, h.can_bus_off ? "yes" : "no"));
  add(out, "limited", enum_text(signal(MessageId::heartbeat, "limited"), h.limited));
  add(out, "stop",
      fmt::format("{}, brake {}", enum_text(signal(MessageId::heartbeat, "stop"), h.stop),
                  h.brake ? "engaged" : "released or none fitted"));
  add(out, "reset cause", enum_text(signal(MessageId::heartbeat, "reset_cause"), h.reset_cause));
  add(out, "commands",
      fmt::format("{} rejected (wraps at 64), {} command frames seen", h.rejected_commands,
                  status.frames.commands));
}

/// "0.1.0+ga2e14617.dirty (protocol 2)": the firmware's --version text and the protocol's.
void add_version(std::string& out, const DriveStatus& status) {
  const VersionStatus& v = status.version;
  if (v.count == 0) {
    add(out, "firmware", "(no version frame yet: the drive sends one at start, then every second)");
    return;
  }
  // A hash of 0 is a build outside a git checkout: "+gunknown", as its --version says.
  const std::string hash = v.git_hash == 0 ? "unknown" : fmt::format("{:08x}", v.git_hash);
  add(out, "firmware",
      fmt::format("{}.{}.{}+g{}{} (protocol {}{})", v.major, v.minor, v.patch, hash,
                  v.dirty ? ".dirty" : "", v.protocol_version,
                  v.protocol_version == protocol::kProtocolVersion
                      ? ""
                      : fmt::format(", this tool speaks {}", protocol::kProtocolVersion)));
}

void add_events(std::string& out, const DriveStatus& status) {
  const FaultReportStatus& f = status.fault_report;
  if (f.count > 0) {
    add(out, "fault report",
        fmt::format("{} at {} ms, latched {}, detail {} ({} reports)",
                    enum_text(signal(MessageId::fault_report, "first_fault"), f.first_fault),
                    f.first_fault_time_ms, fault_bit_names(f.fault_bits), f.detail, f.count));
  }
  const AckStatus& a = status.ack;
  add(out, "last ack",
      a.count == 0 ? std::string("none")
                   : fmt::format("{} counter {}: {}, rejected_total {} (t = {:.3f} s, {} acks)",
                                 message_name(a.message_id), a.counter,
                                 enum_text(signal(MessageId::command_ack, "result"), a.result),
                                 a.rejected_total, a.time_s, a.count));
  const StateChangeStatus& s = status.state_change;
  const protocol::Signal& from = signal(MessageId::state_change, "from");
  add(out, "state changes",
      s.count == 0 ? std::string("none seen")
                   : fmt::format("{} seen, last {} -> {} ({}) at {} ms, transitions {}", s.count,
                                 enum_text(from, s.from), enum_text(from, s.to),
                                 enum_text(signal(MessageId::state_change, "reason"), s.reason),
                                 s.time_ms, s.transitions));
  const TimingStatus& t = status.timing;
  add(out, "timing",
      t.count == 0 ? std::string("none")
                   : fmt::format("exec mean {}, max {}, budget {}, overruns {}",
                                 value(MessageId::timing, "exec_mean_us", t.exec_mean_us),
                                 value(MessageId::timing, "exec_max_us", t.exec_max_us),
                                 value(MessageId::timing, "budget_us", t.budget_us), t.overruns));
}

void add_telemetry(std::string& out, const DriveStatus& status) {
  if (!status.last_row) {
    add(out, "telemetry", "none");
    return;
  }
  const TelemetryRow& r = *status.last_row;
  constexpr MessageId kSf = MessageId::telemetry_speed_flux;
  constexpr MessageId kCu = MessageId::telemetry_current;
  constexpr MessageId kVo = MessageId::telemetry_voltage;
  add(out, "telemetry",
      fmt::format("sample {}: speed {} (ref {}), flux2 {} (ref {})", r.sample,
                  value(kSf, "speed_rad_s", r.speed_rad_s),
                  value(kSf, "speed_ref_rad_s", r.speed_ref_rad_s),
                  value(kSf, "flux2_Wb2", r.flux2_Wb2),
                  value(kSf, "flux2_ref_Wb2", r.flux2_ref_Wb2)));
  add(out, "",
      fmt::format("i_A {}, i_B {}, load {}, v_bus {}", value(kCu, "iA_A", r.iA_A),
                  value(kCu, "iB_A", r.iB_A), value(kCu, "load_Nm", r.load_Nm),
                  value(kCu, "v_bus_V", r.v_bus_V)));
  add(out, "",
      fmt::format("u_alpha {}, u_beta {}", value(kVo, "u_alpha_V", r.u_alpha_V),
                  value(kVo, "u_beta_V", r.u_beta_V)));
}

}  // namespace

std::string render_table(const DriveStatus& status, uint8_t node_id, const std::string& source,
                         const BusInfo* bus) {
  std::string out = fmt::format("drive_monitor: node {} on {}, t = {:.3f} s\n", node_id, source,
                                status.last_time_s);
  add_heartbeat(out, status);
  add_version(out, status);
  add_events(out, status);
  add_telemetry(out, status);
  const FrameCounts& c = status.frames;
  add(out, "frames",
      fmt::format("{} received: {} decoded, {} other nodes, {} unknown, {} wrong length", c.total,
                  c.decoded, c.other_nodes, c.unknown, c.wrong_length));
  add(out, "samples",
      fmt::format("{} rows, {} incomplete, {} stale", c.rows, c.incomplete_samples,
                  c.stale_samples));
  if (bus != nullptr) {
    add(out, "bus",
        fmt::format("{} error frames (last: {}), bus-off {} ({} times), {} unsupported frames",
                    bus->error_frames, bus->last_error_class, bus->bus_off ? "yes" : "no",
                    bus->bus_off_events, bus->unsupported_frames));
  }
  return out;
}

}  // namespace imd::monitor
