#include "firmware/telemetry.hpp"

#include <imd_version.hpp>

#include <algorithm>

#include "firmware/protocol/frame_codec.hpp"
#include "hal/divide_u64.hpp"

namespace imd::firmware {

using protocol::encode_frame;
using protocol::MessageId;

constexpr uint8_t kNoIdentification = 6;  // kIdentifyStepValues' "none"

using protocol::signal_of;
// Counts above 2^24 do not fit a float's mantissa: these are packed as raw bits.
// Copies without their names (protocol/runtime_messages.hpp): the named tables stay out of the
// image.
constexpr protocol::Signal kStateChangeTime =
    protocol::runtime_signal_of(MessageId::state_change, "time_ms");
constexpr protocol::Signal kFirstFaultTime =
    protocol::runtime_signal_of(MessageId::fault_report, "first_fault_time_ms");
constexpr protocol::Signal kGitHash = protocol::runtime_signal_of(MessageId::version, "git_hash");
static_assert(imd::version::kPatch <= signal_of(MessageId::version, "firmware_patch").raw_max(),
              "the version frame carries the patch number in 7 bits");

Telemetry::Telemetry(uint8_t node_id, uint32_t period_ns, int rate_Hz, float ns_per_count) noexcept
    : node_id_(node_id),
      period_ns_(period_ns),
      us_per_count_(ns_per_count * 1e-3f),
      // 32-bit divisions: a 64-bit one is a library call on the MCU (hal/divide_u64.hpp).
      ticks_per_10Hz_(std::max<uint32_t>(1, 100'000'000u / period_ns)),
      next_timing_k_(ticks_per_10Hz_ / 2) {
  if (!set_rate_Hz(rate_Hz)) set_rate_Hz(100);
}

namespace {

/// The next due tick after `due` (<= k) on a schedule of `period` ticks, past k: one step
/// normally, more after skipped ticks. No division: a 64-bit one is a library call on the MCU.
uint64_t next_due(uint64_t due, uint64_t k, uint64_t period) noexcept {
  do {
    due += period;
  } while (due <= k);
  return due;
}

}  // namespace

bool Telemetry::set_rate_Hz(int rate_Hz) noexcept {
  if (rate_Hz < protocol::kFastTelemetryMinHz || rate_Hz > protocol::kFastTelemetryMaxHz) {
    return false;
  }
  rate_Hz_ = rate_Hz;
  // Nearest whole number of ticks; at 10 kHz every rate from 10 to 1000 Hz is within 5 %.
  // Below 2^32: 10^9 / rate plus half a period of at most 2^32 - 1 ns.
  const uint32_t ticks = (1'000'000'000u / uint32_t(rate_Hz) + period_ns_ / 2) / period_ns_;
  fast_period_ticks_ = std::max<uint32_t>(1, ticks);
  return true;
}

uint32_t Telemetry::time_ms(uint64_t tick) const noexcept {
  return static_cast<uint32_t>(hal::divide_u64(tick * period_ns_, 1'000'000u));
}

void Telemetry::send(hal::CanBus& can, const hal::CanFrame& frame) noexcept {
  if (!version_sent_) {  // the first frame of a start: the version goes before it
    version_sent_ = true;
    send_version(can);
  }
  if (!can.try_send(frame)) ++dropped_;
}

void Telemetry::send_version(hal::CanBus& can) noexcept {
  hal::CanFrame frame = encode_frame(
      node_id_, MessageId::version,
      {float(protocol::kProtocolVersion), float(imd::version::kMajor), float(imd::version::kMinor),
       float(imd::version::kPatch), imd::version::kDirty ? 1.0f : 0.0f});
  protocol::set_raw(frame.data, kGitHash, imd::version::kGitHash);
  if (!can.try_send(frame)) ++dropped_;
}

template <typename T>
void Telemetry::publish(uint64_t k, hal::CanBus& can, const TickRecord<T>& r,
                        const DriveStatus& status, const StateMachine& machine,
                        const ExecutionStats& execution, uint32_t budget_ns) noexcept {
  send_state_changes(can, machine);  // events go at once
  // The common tick: no cyclic frame due, none waiting (one 64-bit comparison for three).
  if (k < next_due_k_ && pending_ == 0) return;
  if (k >= next_heartbeat_k_) {
    next_heartbeat_k_ = next_due(next_heartbeat_k_, k, ticks_per_10Hz_);
    pending_ |= kHeartbeatDue;
    // A commissioning ran: its progress with each heartbeat.
    if (status.identify_step != kNoIdentification) pending_ |= kIdentifyProgressDue;
    // Every tenth heartbeat, so that a host that joins the bus later learns the version too.
    if (++heartbeats_since_version_ >= kHeartbeatsPerVersion) {
      heartbeats_since_version_ = 0;
      pending_ |= kVersionDue;
    }
  }
  if (k >= next_timing_k_) {  // between heartbeats, to spread the load
    next_timing_k_ = next_due(next_timing_k_, k, ticks_per_10Hz_);
    pending_ |= kTimingDue | kStageTiming1Due | kStageTiming2Due;
    timed_stages_ = r.stage_counts;  // both stage-timing frames from the same tick
  }
  bool sample = false;
  if (k >= next_fast_k_) {  // a fast sample: its three frames together
    next_fast_k_ = next_due(next_fast_k_, k, fast_period_ticks_);
    send(can, encode_frame(node_id_, MessageId::telemetry_speed_flux,
                           {float(r.omega_est_rad_s), float(r.omega_ref_rad_s),
                            float(r.controlled_flux2_Wb2), float(r.controlled_flux2_ref_Wb2)}));
    send(can, encode_frame(node_id_, MessageId::telemetry_current,
                           {float(r.i_s_est_AB_A.x()), float(r.i_s_est_AB_A.y()),
                            float(r.load_est_Nm), float(r.v_bus_V)}));
    send(can, encode_frame(node_id_, MessageId::telemetry_voltage,
                           {float(r.u_alphabeta_V.x()), float(r.u_alphabeta_V.y()),
                            float(sample_count_++), float(r.rr_scale)}));
    sample = true;
  }
  next_due_k_ = std::min({next_heartbeat_k_, next_timing_k_, next_fast_k_});
  // A frame costs the tick hundreds of instructions: with enough ticks between the 10 Hz
  // frames, the other cyclic frames go one a tick, on ticks without a sample (unless a sample
  // takes every tick), the first due in this order; each carries its tick's values. A slower
  // loop has the time to send them all at once, and too few ticks to spread them.
  const bool spread = ticks_per_10Hz_ >= kSpreadMinTicks;
  if (spread && sample && fast_period_ticks_ > 1) return;
  while (pending_ != 0) {
    const uint16_t due = pending_ & uint16_t(-pending_);  // the lowest bit set
    pending_ = uint16_t(pending_ & ~due);
    send_cyclic(due, k, can, status, machine, execution, budget_ns);
    if (spread) break;
  }
}

template void Telemetry::publish(uint64_t, hal::CanBus&, const TickRecord<float>&,
                                 const DriveStatus&, const StateMachine&, const ExecutionStats&,
                                 uint32_t) noexcept;
template void Telemetry::publish(uint64_t, hal::CanBus&, const TickRecord<double>&,
                                 const DriveStatus&, const StateMachine&, const ExecutionStats&,
                                 uint32_t) noexcept;

void Telemetry::send_cyclic(uint16_t due, uint64_t k, hal::CanBus& can, const DriveStatus& status,
                            const StateMachine& machine, const ExecutionStats& execution,
                            uint32_t budget_ns) noexcept {
  switch (due) {
    case kHeartbeatDue:
      send_heartbeat(can, status, machine);
      break;
    case kIdentifyProgressDue: {
      // In 32 bits (a 64-bit conversion is a library call on the MCU): 2^32 ticks are days.
      const uint64_t ticks = k - status.identify_start_tick;
      const float seconds = float(static_cast<uint32_t>(std::min<uint64_t>(ticks, UINT32_MAX))) *
                            float(period_ns_) * 1e-9f;
      send(can, encode_frame(node_id_, MessageId::identify_progress,
                             {float(status.identify_step), status.identify_fraction,
                              float(status.identify_failure), seconds}));
      break;
    }
    case kVersionDue:
      send_version(can);
      break;
    case kTimingDue:
      send(can, encode_frame(
                    node_id_, MessageId::timing,
                    {execution.mean_us(), float(execution.max_ns) * 1e-3f,
                     float(static_cast<uint32_t>(std::min<uint64_t>(execution.overruns, 0xFFFF))),
                     float(budget_ns) * 1e-3f}));
      break;
    case kStageTiming1Due:
    case kStageTiming2Due:
      send_stage_timing(can, timed_stages_, due == kStageTiming1Due ? 0 : 4);
      break;
    default:
      break;
  }
}

void Telemetry::send_stage_timing(hal::CanBus& can, const StageCounts& c, int first) noexcept {
  const float u = us_per_count_;
  send(can,
       encode_frame(node_id_, first == 0 ? MessageId::stage_timing_1 : MessageId::stage_timing_2,
                    {float(c[first]) * u, float(c[first + 1]) * u, float(c[first + 2]) * u,
                     float(c[first + 3]) * u}));
}

void Telemetry::final_heartbeat(hal::CanBus& can, const DriveStatus& status,
                                const StateMachine& machine) noexcept {
  send_state_changes(can, machine);
  send_heartbeat(can, status, machine);
}

void Telemetry::send_state_changes(hal::CanBus& can, const StateMachine& machine) noexcept {
  Transition t;
  while (transitions_sent_ < machine.count()) {
    if (machine.logged(transitions_sent_, t)) {
      hal::CanFrame frame = encode_frame(
          node_id_, MessageId::state_change,
          {float(t.from), float(t.to), float(t.reason), float((transitions_sent_ + 1) & 0xFF)});
      // Whole milliseconds exceed a float's 24-bit mantissa after 4.6 h: set the raw bits.
      protocol::set_raw(frame.data, kStateChangeTime, time_ms(t.tick));
      send(can, frame);
    }
    ++transitions_sent_;  // a transition that fell out of the log is skipped
  }
}

void Telemetry::send_heartbeat(hal::CanBus& can, const DriveStatus& status,
                               const StateMachine& machine) noexcept {
  hal::CanFrame frame = encode_frame(
      node_id_, MessageId::heartbeat,
      {float(status.state), float(status.first_fault), float(heartbeat_count_++),
       float(status.command_counter), float(status.controller), status.can_bus_off ? 1.0f : 0.0f,
       float(status.rejected_commands & 0x3F), float(status.limited), float(machine.count() & 0xFF),
       float(status.stop), status.brake_engaged ? 1.0f : 0.0f, float(status.reset_cause)});
  protocol::set_fault_bits(frame.data, protocol::kHeartbeatFaultWordBit, status.fault_bits);
  send(can, frame);
}

void Telemetry::report_fault(hal::CanBus& can, const DriveStatus& status) noexcept {
  hal::CanFrame frame = encode_frame(node_id_, MessageId::fault_report,
                                     {float(status.first_fault), 0.0f, float(status.fault_detail)});
  protocol::set_raw(frame.data, kFirstFaultTime, time_ms(status.first_fault_tick));
  protocol::set_fault_bits(frame.data, protocol::kFaultReportFaultWordBit, status.fault_bits);
  send(can, frame);
}

void Telemetry::acknowledge(hal::CanBus& can, const protocol::Decoded& decoded,
                            uint32_t rejected_total) noexcept {
  send(can, encode_frame(node_id_, MessageId::command_ack,
                         {float(decoded.message_id), float(decoded.counter), float(decoded.result),
                          float(std::min<uint32_t>(rejected_total, 0xFFFF))}));
}

void Telemetry::parameter_value(hal::CanBus& can, uint8_t field, protocol::ParameterOp op,
                                uint8_t status, float value, bool complete, bool saved) noexcept {
  send(can, encode_frame(node_id_, MessageId::parameter_value,
                         {float(field), float(op), float(status), value, complete ? 1.0f : 0.0f,
                          saved ? 1.0f : 0.0f}));
}

}  // namespace imd::firmware
