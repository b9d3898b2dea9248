#pragma once
/// What the drive sends on CAN, and when (docs/can/protocol.md): the heartbeat and the timing
/// frame at 10 Hz, fast telemetry at a configurable 10..1000 Hz (three frames per sample, in
/// one tick, the voltage frame last), and event frames for state changes, faults and command
/// results. From 20 ticks per 100 ms, a tick sends the fast sample or one other cyclic frame
/// (both only when a sample takes every tick). The
/// version frame goes first at each start, before whatever frame the drive sends first, and
/// then with every tenth heartbeat.
/// Frames go to the HAL's non-blocking transmit queue; a full queue drops the frame and counts
/// it. Tick context, no heap.
#include <cstdint>

#include "firmware/drive_state.hpp"
#include "firmware/execution_stats.hpp"
#include "firmware/protection/stop_category.hpp"
#include "firmware/protocol/commands.hpp"
#include "firmware/state_machine.hpp"
#include "firmware/tick_record.hpp"
#include "hal/can_bus.hpp"

namespace imd::firmware {

/// The drive's status as the heartbeat and the fault report carry it.
struct DriveStatus {
  DriveState state = DriveState::calibrating;
  uint16_t fault_bits = 0;
  FaultCode first_fault = FaultCode::none;
  uint64_t first_fault_tick = 0;
  uint8_t fault_detail = 0;
  uint8_t controller = 0;  ///< ControllerKind: 0 dsmc, 1 iol, 2 ifoc
  uint8_t command_counter = 0;
  uint32_t rejected_commands = 0;
  bool can_bus_off = false;
  Limitation limited = Limitation::none;  ///< a limit holds the running drive back
  StopCategory stop = StopCategory::none;  ///< how the latched fault stops the drive
  /// The holding brake engaged: a brake line is configured and not driven (false without one).
  /// False here so that a drive without a brake line never reports one; a drive with one sets
  /// it true at construction, before its first heartbeat (its line starts undriven).
  bool brake_engaged = false;
  uint8_t reset_cause = 0;                 ///< why the board last started (hal::ResetCause)
  // The last commissioning run: its step (kIdentifyStepValues; 6 none yet), progress and end.
  uint8_t identify_step = 6;
  float identify_fraction = 0.0f;
  uint8_t identify_failure = 0;
  uint64_t identify_start_tick = 0;
};

class Telemetry {
 public:
  /// `period_ns`: the control period; `ns_per_count`: of the execution clock that times the
  /// stages.
  Telemetry(uint8_t node_id, uint32_t period_ns, int rate_Hz, float ns_per_count = 1.0f) noexcept;

  /// Sets the fast-telemetry rate; false (unchanged) outside 10..1000 Hz.
  bool set_rate_Hz(int rate_Hz) noexcept;
  int rate_Hz() const noexcept { return rate_Hz_; }

  /// A state_change frame for each new transition; the fast sample's three frames if one is
  /// due at tick k; the first of the other cyclic frames due by k and not yet sent, unless a
  /// sample went out (frames due together go out on the ticks that follow, in a fixed order;
  /// all at once below 20 ticks per 100 ms).
  /// T: the drive's arithmetic (float and double are instantiated).
  template <typename T>
  void publish(uint64_t k, hal::CanBus& can, const TickRecord<T>& record, const DriveStatus& status,
               const StateMachine& machine, const ExecutionStats& execution,
               uint32_t budget_ns) noexcept;
  /// A state_change frame for each transition not yet reported, then a heartbeat: the last
  /// frames of a drive that is shutting down.
  void final_heartbeat(hal::CanBus& can, const DriveStatus& status,
                       const StateMachine& machine) noexcept;
  /// The fault_report frame, sent when a fault latches.
  void report_fault(hal::CanBus& can, const DriveStatus& status) noexcept;
  /// The command_ack frame for a command frame addressed to this node.
  void acknowledge(hal::CanBus& can, const protocol::Decoded& decoded,
                   uint32_t rejected_total) noexcept;

  /// The parameter_value frame: the answer to a parameter_access.
  void parameter_value(hal::CanBus& can, uint8_t field, protocol::ParameterOp op, uint8_t status,
                       float value, bool complete, bool saved) noexcept;

  uint32_t dropped_frames() const noexcept { return dropped_; }

 private:
  void send(hal::CanBus& can, const hal::CanFrame& frame) noexcept;
  void send_version(hal::CanBus& can) noexcept;
  void send_state_changes(hal::CanBus& can, const StateMachine& machine) noexcept;
  void send_heartbeat(hal::CanBus& can, const DriveStatus& status,
                      const StateMachine& machine) noexcept;
  uint32_t time_ms(uint64_t tick) const noexcept;
  /// stage_timing_1 (`first` 0: the first four stages) or stage_timing_2 (4: the last four).
  void send_stage_timing(hal::CanBus& can, const StageCounts& counts, int first) noexcept;

  /// One cyclic frame other than the fast sample's (`due`: one of the k...Due bits).
  void send_cyclic(uint16_t due, uint64_t k, hal::CanBus& can, const DriveStatus& status,
                   const StateMachine& machine, const ExecutionStats& execution,
                   uint32_t budget_ns) noexcept;

  // The cyclic frames due and not yet sent, one bit each; publish() sends the lowest first.
  static constexpr uint16_t kHeartbeatDue = 1u << 0, kIdentifyProgressDue = 1u << 1,
                            kVersionDue = 1u << 2, kTimingDue = 1u << 3,
                            kStageTiming1Due = 1u << 4, kStageTiming2Due = 1u << 5;
  uint16_t pending_ = 0;
  // Spread over ticks from 20 ticks per 100 ms (a 5 ms period): at least 10 ticks without a
  // sample then, for the at most 3 frames due at once, before they fall due again.
  static constexpr uint64_t kSpreadMinTicks = 20;
  StageCounts timed_stages_{};  ///< the stage counts the stage-timing frames carry

  uint8_t node_id_;
  uint32_t period_ns_;
  float us_per_count_;
  uint64_t ticks_per_10Hz_;
  uint64_t fast_period_ticks_ = 1;
  // The ticks at which the cyclic frames are due next (heartbeat at 0, the timing frame
  // half a heartbeat period later, fast telemetry at 1: the first ticks send the version and
  // the heartbeat, then the first sample); a new rate applies from the next.
  uint64_t next_heartbeat_k_ = 0, next_timing_k_, next_fast_k_ = 1;
  uint64_t next_due_k_ = 0;  ///< the earliest of the three
  int rate_Hz_ = 100;
  uint8_t heartbeat_count_ = 0;
  uint8_t sample_count_ = 0;
  uint32_t transitions_sent_ = 0;
  uint32_t dropped_ = 0;
  bool version_sent_ = false;
  // The version frame's period in heartbeats, from the table (1000 ms / 100 ms).
  static constexpr uint8_t kHeartbeatsPerVersion = static_cast<uint8_t>(
      protocol::message(protocol::MessageId::version).period_ms /
      protocol::message(protocol::MessageId::heartbeat).period_ms);
  uint8_t heartbeats_since_version_ = 0;
};

}  // namespace imd::firmware
