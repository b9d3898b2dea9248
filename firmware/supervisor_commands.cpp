// The supervisor's command handling: frames from CAN, checked by the protocol decoder, applied
// to the state machine and the references. Tick context, bounded work per tick.
#include <cmath>
#include <limits>

#include "firmware/supervisor.hpp"

namespace imd::firmware {

/// Frames read per tick; more wait in the receive queue for the next tick.
inline constexpr int kMaxFramesPerTick = 4;

template <typename T>
void Supervisor<T>::receive_commands(uint64_t k, bool& restarted) noexcept {
  // The bank's stage read here: most ticks have no answer to take.
  const ParameterBank* bank = wiring_.parameters;
  if (bank != nullptr && bank->stage() == ParameterBank::Stage::answered) answer_served_access(k);
  hal::CanFrame frame;
  for (int n = 0; n < kMaxFramesPerTick && wiring_.can->try_receive(frame); ++n) {
    protocol::Decoded d = decoder_.decode(frame);
    if (!d.for_this_node) continue;
    if (d.result == protocol::CommandResult::accepted) {
      last_command_tick_ = k;  // any valid command feeds the watchdog
      d.result = apply(d.command, k, restarted);
      if (d.result != protocol::CommandResult::accepted) decoder_.count_refused(d.result);
    }
    wiring_.telemetry.acknowledge(*wiring_.can, d, decoder_.rejected_total());
  }
}

template <typename T>
void Supervisor<T>::enable(uint64_t k, bool& restarted) noexcept {
  ++generation_;  // the ramp's limit
  if (!machine_.go(DriveState::magnetizing, TransitionReason::enable, k)) return;
  magnetizing_start_tick_ = k;
  last_command_tick_ = k;
  ramp_.set_max_step(command_accel_step_rad_s_);
  restarted = true;
}

template <typename T>
protocol::CommandResult Supervisor<T>::clear_faults(uint64_t k, bool& restarted) noexcept {
  // Not before a fault's controlled stop has ended in STO; without a fault, nothing to clear.
  if (fault_stop_) return protocol::CommandResult::not_allowed;
  if (machine_.state() != DriveState::fault) return protocol::CommandResult::accepted;
  // A fault during the offset calibration leaves the offsets unknown: calibrate again.
  const DriveState next = calibrated_ ? rest_state() : DriveState::calibrating;
  if (!machine_.go(next, TransitionReason::clear_faults, k)) {
    return protocol::CommandResult::accepted;
  }
  status_.fault_bits = 0;
  status_.first_fault = FaultCode::none;
  status_.fault_detail = 0;
  status_.stop = StopCategory::none;
  restarted = true;
  return protocol::CommandResult::accepted;
}

template <typename T>
protocol::CommandResult Supervisor<T>::apply(const protocol::Command& c, uint64_t k,
                                             bool& restarted) noexcept {
  using protocol::CommandKind;
  using protocol::CommandResult;
  ++generation_;  // any command may change the references, the ramp or the state
  const DriveState s = machine_.state();
  switch (c.kind) {
    case CommandKind::emergency_stop: {
      Trip stop;  // a command, not a check: latched at once
      stop.add(FaultCode::emergency_stop);
      latch(stop, k);
      return CommandResult::accepted;
    }
    case CommandKind::enable:
      if (!enable_input_) return CommandResult::not_allowed;  // the board's interlock is open
      // A parameter access in progress may change the model: not while it could run.
      if (wiring_.parameters != nullptr && wiring_.parameters->busy()) {
        return CommandResult::not_allowed;
      }
      if (s == DriveState::idle) enable(k, restarted);
      return s == DriveState::idle || s == DriveState::magnetizing || s == DriveState::running
                 ? CommandResult::accepted
                 : CommandResult::not_allowed;
    case CommandKind::disable:
      commanded_.set_speed(T(0));          // a later enable waits for a new speed
      if (s == DriveState::identifying) {  // the commissioning is aborted, the PWM goes off
        identification_ended(k, false, 5);  // aborted
      } else if (s == DriveState::magnetizing) {  // no motion to stop yet: the PWM goes off
        machine_.go(DriveState::idle, TransitionReason::disable, k);
      } else if (s == DriveState::running) {  // (a fault's stop runs on: disable is moot)
        machine_.go(DriveState::stopping, TransitionReason::disable, k);
        stop_start_tick_ = k;
        ramp_.set_max_step(stop_accel_step_rad_s_);
      }
      return CommandResult::accepted;
    case CommandKind::clear_faults:
      return clear_faults(k, restarted);
    case CommandKind::set_speed:
      if (!commands_over_can_) return CommandResult::not_allowed;
      commanded_.set_speed(T(c.value));
      return CommandResult::accepted;
    case CommandKind::set_flux:
      if (!commands_over_can_) return CommandResult::not_allowed;
      if (controlled_flux_ == ControlledFlux::stator) {
        commanded_.set_stator_flux2(T(c.value));
      } else {
        commanded_.set_flux2(T(c.value));
      }
      return CommandResult::accepted;
    case CommandKind::select_controller: {
      const long index = std::lround(c.value);
      if (index < 0 || index >= kControllerCount) return CommandResult::out_of_range;
      const auto wanted = static_cast<ControllerKind>(index);
      if (!law_in_image(wanted)) return CommandResult::not_in_image;
      if (laws_ == nullptr) return CommandResult::not_allowed;  // no motor model
      // Only at rest; a law that follows no speed reference only with references of its own.
      const bool speed_capable = laws_->law(wanted).follows_speed() || !commands_over_can_;
      if (s != DriveState::idle || !speed_capable) return CommandResult::not_allowed;
      select(wanted);
      return CommandResult::accepted;
    }
    case CommandKind::set_telemetry_rate:
      return wiring_.telemetry.set_rate_Hz(static_cast<int>(std::lround(c.value)))
                 ? CommandResult::accepted
                 : CommandResult::out_of_range;
    case CommandKind::parameter_access:
      return access_parameter(c, k, restarted);
    case CommandKind::identify: {
      if (!kCommissioningInImage) return CommandResult::not_in_image;
      // Planned from the record's nameplate by the service loop (Drive::service); running
      // once it answers.
      const bool at_rest = s == DriveState::idle || s == DriveState::unconfigured;
      if (!at_rest || !enable_input_ || wiring_.parameters == nullptr) {
        return CommandResult::not_allowed;
      }
      // The access carries the bus voltage the test is planned on, and in its field whether
      // the rotor may turn.
      const ParameterAccess request{protocol::ParameterOp::identify,
                                    static_cast<uint8_t>(c.value == 1.0f ? 1 : 0),
                                    float(v_bus_V_), true};
      if (!wiring_.parameters->submit(request)) return CommandResult::not_allowed;
      // A run of its own from here: no progress frame until it starts or fails, so every
      // identify_progress after this command's ack reports this run, not the one before.
      status_.identify_step = 6;  // none
      status_.identify_failure = 0;
      status_.identify_fraction = 0.0f;
      status_.identify_start_tick = k;
      return CommandResult::accepted;
    }
  }
  return CommandResult::unknown_message;
}

template <typename T>
protocol::CommandResult Supervisor<T>::access_parameter(const protocol::Command& c, uint64_t,
                                                        bool&) noexcept {
  using protocol::CommandResult;
  ParameterBank* bank = wiring_.parameters;
  if (bank == nullptr) return CommandResult::not_allowed;
  const DriveState s = machine_.state();
  ParameterAnswer refused;
  refused.access = {c.op, c.field, c.value, s == DriveState::idle || s == DriveState::unconfigured};
  refused.value = std::numeric_limits<float>::quiet_NaN();
  refused.complete = record_complete_;
  refused.saved = record_saved_;
  // Checked and served outside the tick (Drive::service); answered when served.
  if (c.op == protocol::ParameterOp::write && !refused.access.at_rest) {
    refused.status = ParameterStatus::not_idle;
  } else if (!bank->submit(refused.access)) {
    refused.status = ParameterStatus::busy;
  } else {
    return CommandResult::accepted;
  }
  answer_parameter(refused);
  return CommandResult::not_allowed;
}

template <typename T>
void Supervisor<T>::answer_served_access(uint64_t k) noexcept {
  if (wiring_.parameters == nullptr) return;
  const std::optional<ParameterAnswer> a = wiring_.parameters->take_answer();
  if (!a) return;
  record_complete_ = a->complete;
  record_saved_ = a->saved;
  if (a->access.op == protocol::ParameterOp::identify) {
    if (a->status == ParameterStatus::ok &&
        machine_.go(DriveState::identifying, TransitionReason::identify, k)) {
      status_.identify_step = 0;
      status_.identify_failure = 0;
      status_.identify_fraction = 0.0f;
      status_.identify_start_tick = k;
    } else {
      status_.identify_start_tick = k;  // the attempt's own time base
      status_.identify_step = 5;                                   // failed
      status_.identify_failure = a->status == ParameterStatus::not_set ? 4 : 5;  // no nameplate
    }
    status_.state = machine_.state();
    return;
  }
  if (a->access.op == protocol::ParameterOp::identified) {
    if (a->status != ParameterStatus::ok && a->status != ParameterStatus::store_failed) {
      status_.identify_step = 5;
      status_.identify_failure = 6;  // invalid_record
    }
    return;  // the new model's attachment moves the drive on (configured)
  }
  answer_parameter(*a);
  // The drive lets go of its model at the end of this tick; unconfigured until the new one.
  if (a->apply && machine_.state() == DriveState::idle) {
    machine_.go(DriveState::unconfigured, TransitionReason::parameters_written, k);
    status_.state = machine_.state();
  }
}

template <typename T>
void Supervisor<T>::answer_parameter(const ParameterAnswer& a) noexcept {
  if (wiring_.can == nullptr) return;
  wiring_.telemetry.parameter_value(*wiring_.can, a.access.field, a.access.op,
                                    static_cast<uint8_t>(a.status), a.value, a.complete, a.saved);
}

// The class is instantiated in supervisor.cpp; these members are defined here.
#define IMD_INSTANTIATE_COMMANDS(T)                                                         \
  template void Supervisor<T>::receive_commands(uint64_t, bool&) noexcept;                  \
  template void Supervisor<T>::enable(uint64_t, bool&) noexcept;                            \
  template protocol::CommandResult Supervisor<T>::clear_faults(uint64_t, bool&) noexcept;   \
  template protocol::CommandResult Supervisor<T>::apply(const protocol::Command&, uint64_t, \
                                                        bool&) noexcept;                    \
  template protocol::CommandResult Supervisor<T>::access_parameter(                         \
      const protocol::Command&, uint64_t, bool&) noexcept;                                  \
  template void Supervisor<T>::answer_served_access(uint64_t) noexcept;                     \
  template void Supervisor<T>::answer_parameter(const ParameterAnswer&) noexcept;
IMD_INSTANTIATE_COMMANDS(float)
IMD_INSTANTIATE_COMMANDS(double)
#undef IMD_INSTANTIATE_COMMANDS

}  // namespace imd::firmware
