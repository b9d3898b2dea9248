// The drive's command handling: frames from CAN, checked by the protocol decoder, applied to
// the state machine and the references. Tick context, bounded work per tick.
#include <cmath>

#include "firmware/drive.hpp"

namespace imd::firmware {

/// Frames read per tick; more wait in the receive queue for the next tick.
inline constexpr int kMaxFramesPerTick = 4;

template <typename T>
void Drive<T>::receive_commands(uint64_t k) noexcept {
  if (hw_.can == nullptr) return;
  hal::CanFrame frame;
  for (int n = 0; n < kMaxFramesPerTick && hw_.can->try_receive(frame); ++n) {
    protocol::Decoded d = decoder_.decode(frame);
    if (!d.for_this_node) continue;
    if (d.result == protocol::CommandResult::accepted) {
      last_command_tick_ = k;  // any valid command feeds the watchdog
      d.result = apply(d.command, k);
      if (d.result == protocol::CommandResult::not_allowed) decoder_.count_not_allowed();
    }
    telemetry_.acknowledge(*hw_.can, d, decoder_.rejected_total());
  }
}

template <typename T>
void Drive<T>::enable(uint64_t k) noexcept {
  if (!machine_.go(DriveState::magnetizing, TransitionReason::enable, k)) return;
  magnetizing_start_tick_ = k;
  last_command_tick_ = k;
  speed_ramp_.set_max_step(limits_.command_accel_step_rad_s);
  adc_stuck_check_.reset();
  phase_loss_check_.reset();
  encoder_check_.reset();
}

template <typename T>
void Drive<T>::clear_faults(uint64_t k) noexcept {
  // A fault during the offset calibration leaves the offsets unknown: calibrate again.
  const DriveState next = calibrated_ ? DriveState::idle : DriveState::calibrating;
  if (!machine_.go(next, TransitionReason::clear_faults, k)) return;
  if (!calibrated_) {
    calibration_count_ = 0;
    for (int64_t& sum : calibration_sum_) sum = 0;
  }
  status_.fault_bits = 0;
  status_.first_fault = FaultCode::none;
  status_.fault_detail = 0;
  encoder_check_.reset();
  adc_stuck_check_.reset();
  phase_loss_check_.reset();
}

template <typename T>
protocol::CommandResult Drive<T>::apply(const protocol::Command& c, uint64_t k) noexcept {
  using protocol::CommandKind;
  using protocol::CommandResult;
  const DriveState s = machine_.state();
  switch (c.kind) {
    case CommandKind::emergency_stop:
      trip(FaultCode::emergency_stop, k);
      return CommandResult::accepted;
    case CommandKind::enable:
      if (!enable_input_) return CommandResult::not_allowed;  // the board's interlock is open
      if (s == DriveState::idle) enable(k);
      return s == DriveState::idle || s == DriveState::magnetizing || s == DriveState::running
                 ? CommandResult::accepted
                 : CommandResult::not_allowed;
    case CommandKind::disable:
      commanded_.set_speed(T(0));           // a later enable waits for a new speed
      if (s == DriveState::magnetizing) {  // no motion to stop yet
        pwm_off();
        machine_.go(DriveState::idle, TransitionReason::disable, k);
      } else if (s == DriveState::running) {
        machine_.go(DriveState::stopping, TransitionReason::disable, k);
        stop_start_tick_ = k;
        speed_ramp_.set_max_step(limits_.stop_accel_step_rad_s);
      }
      return CommandResult::accepted;
    case CommandKind::clear_faults:
      clear_faults(k);
      return CommandResult::accepted;
    case CommandKind::set_speed:
      if (!config_.commands_over_can) return CommandResult::not_allowed;
      commanded_.set_speed(T(c.value));
      return CommandResult::accepted;
    case CommandKind::set_flux:
      if (!config_.commands_over_can) return CommandResult::not_allowed;
      if (controller_ == ControllerKind::iol) {
        commanded_.set_stator_flux2(T(c.value));
      } else {
        commanded_.set_flux2(T(c.value));
      }
      return CommandResult::accepted;
    case CommandKind::select_controller: {
      const ControllerKind wanted = c.value == 1.0f ? ControllerKind::iol : ControllerKind::dsmc;
      // Only at rest; the current-fed law follows a speed reference only with its speed loop.
      const bool speed_capable =
          wanted == ControllerKind::dsmc || config_.outer_speed_loop || !config_.commands_over_can;
      if (s != DriveState::idle || !speed_capable) return CommandResult::not_allowed;
      controller_ = wanted;
      status_.controller = wanted == ControllerKind::iol ? 1 : 0;
      return CommandResult::accepted;
    }
    case CommandKind::set_telemetry_rate:
      return telemetry_.set_rate_Hz(static_cast<int>(std::lround(c.value)))
                 ? CommandResult::accepted
                 : CommandResult::out_of_range;
  }
  return CommandResult::unknown_message;
}

// The class is instantiated in drive.cpp; these members are defined here.
#define IMD_INSTANTIATE_COMMANDS(T)                            \
  template void Drive<T>::receive_commands(uint64_t) noexcept; \
  template void Drive<T>::enable(uint64_t) noexcept;           \
  template void Drive<T>::clear_faults(uint64_t) noexcept;     \
  template protocol::CommandResult Drive<T>::apply(const protocol::Command&, uint64_t) noexcept;
IMD_INSTANTIATE_COMMANDS(float)
IMD_INSTANTIATE_COMMANDS(double)
#undef IMD_INSTANTIATE_COMMANDS

}  // namespace imd::firmware
