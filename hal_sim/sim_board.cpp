#include "hal_sim/sim_board.hpp"

#include <algorithm>
#include <cmath>

#include "control/svpwm.hpp"
#include "hal_sim/switching_inverter.hpp"

namespace imd::sim {

namespace {

/// The inverter's error over one period, as the plant evaluates it.
class InverterError final : public CurrentDependentVoltage {
 public:
  InverterError(const InverterNonideality& inverter, const hal::PhaseDuties& duty,
                double v_bus_V, double period_s) noexcept
      : inverter_(inverter), duty_(duty), v_bus_V_(v_bus_V), period_s_(period_s) {}
  Vec2 error_V(const Vec2& i_s_alphabeta_A) const noexcept override {
    return inverter_error_V(inverter_, duty_, v_bus_V_, period_s_, i_s_alphabeta_A);
  }

 private:
  const InverterNonideality& inverter_;
  const hal::PhaseDuties& duty_;
  double v_bus_V_, period_s_;
};

}  // namespace

SimBoard::SimBoard(const control::MotorParameters& motor, const SimBoardConfig& config)
    : config_(config),
      plant_(motor, {config.period_s, config.substeps, config.integrator}),
      Rs0_Ohm_(motor.Rs_Ohm),
      Rr0_Ohm_(motor.Rr_Ohm),
      adc_model_(config.adc, config.seed),
      pwm_(static_cast<float>(config.period_s)),
      encoder_(config.encoder_cpr),
      adc_(adc_model_.scale()),
      timer_(static_cast<uint32_t>(std::lround(config.period_s * 1e9))),
      v_bus_V_(config.v_bus_V) {}

void SimBoard::latch_sensors() {
  const PlantState& s = plant_.state();
  const auto i_abc = control::inverse_clarke(s.i_s_alphabeta_A);
  if (!adc_stuck_) adc_.latch(adc_model_.convert({i_abc[0], i_abc[1], i_abc[2]}, v_bus_V_));
  if (!encoder_frozen_) {
    encoder_.latch(encoder_count(s.theta_mech_rad, config_.encoder_cpr) + encoder_offset_counts_);
  }
}

void SimBoard::run_tick() {
  begin_period();
  timer_.fire();
  end_period();
}

void SimBoard::begin_period() {
  latch_sensors();
}

void SimBoard::drift_resistances() noexcept {
  const ResistanceDrift& d = config_.drift;
  const double share = std::min(plant_.time_s() / d.duration_s, 1.0);
  plant_.set_resistances(Rs0_Ohm_ * (1.0 + (d.Rs_scale_end - 1.0) * share),
                         Rr0_Ohm_ * (1.0 + (d.Rr_scale_end - 1.0) * share));
}

void SimBoard::update_brake() noexcept {
  const HoldingBrake& b = config_.brake;
  const bool released = gpio_.read(HoldingBrake::kLine);
  const double now_s = plant_.time_s();
  if (released != brake_line_released_) {
    brake_line_released_ = released;
    brake_line_since_s_ = now_s;
  }
  const double delay_s = released ? b.release_delay_s : b.engage_delay_s;
  if (now_s - brake_line_since_s_ >= delay_s - 1e-12) brake_engaged_ = !released;
  plant_.set_brake_torque(brake_engaged_ ? b.holding_torque_Nm : 0.0);
}

void SimBoard::end_period() {
  if (config_.drift.active()) drift_resistances();
  update_brake();
  const double load_now_Nm = load_Nm();
  // What the firmware wrote this tick acts now (no latency) or from the next tick.
  const Vec2 written_analog(analog_.v_A_V(), analog_.v_B_V());
  const Vec2 written_current(current_source_.iA_A(), current_source_.iB_A());
  if (config_.pwm_latency_ticks == 0) {
    active_duty_ = pwm_.written();
    active_analog_input_V_ = written_analog;
    active_current_AB_A_ = written_current;
  }
  const PlantState& now = plant_.state();
  Vec2 current_now = now.i_s_alphabeta_A;  // continuous unless a current source steps it
  if (!pwm_.enabled()) {
    current_now.setZero();
  } else if (config_.current_source) {
    current_now = control::Rotation<double>::from_angle(plant_.pole_pairs() * now.theta_mech_rad)
                      .apply(active_current_AB_A_);
  }
  start_torque_Nm_ = plant_.torque_Nm(current_now, now.flux_r_alphabeta_Wb);
  start_flux_s_alphabeta_Wb_ = plant_.flux_s_alphabeta_Wb(current_now);
  start_current_alphabeta_A_ = current_now;

  if (!pwm_.enabled()) {
    applied_voltage_V_.setZero();
    plant_.step_current_fed(Vec2::Zero(), load_now_Nm);
  } else if (config_.current_source) {
    applied_voltage_V_.setZero();  // not defined for an ideal current source
    plant_.step_current_fed(active_current_AB_A_, load_now_Nm);
  } else if (config_.inner_feedback == InnerFeedback::ideal_analog) {
    applied_voltage_V_ = plant_.analog_feedback_voltage_V(active_analog_input_V_);
    plant_.step_analog_feedback(active_analog_input_V_, load_now_Nm);
  } else if (config_.switching_inverter) {
    const PwmPeriod pwm =
        switching_period(config_.inverter, active_duty_, v_bus_V_, config_.period_s,
                         now.i_s_alphabeta_A);
    applied_voltage_V_ = pwm.average_V();
    plant_.step_voltage_segments(pwm.segments.data(), pwm.count, load_now_Nm);
  } else if (config_.inverter.ideal()) {
    applied_voltage_V_ = inverter_output_V(active_duty_, v_bus_V_);
    plant_.step_voltage(applied_voltage_V_, load_now_Nm);
  } else {
    const InverterError error(config_.inverter, active_duty_, v_bus_V_, config_.period_s);
    const Vec2 ideal_V = inverter_output_V(active_duty_, v_bus_V_);
    applied_voltage_V_ = ideal_V + error.error_V(now.i_s_alphabeta_A);  // at the period's start
    plant_.step_voltage(ideal_V, error, load_now_Nm);
  }
  if (config_.pwm_latency_ticks != 0) {
    active_duty_ = pwm_.written();
    active_analog_input_V_ = written_analog;
    active_current_AB_A_ = written_current;
  }
}

bool SimBoard::inject(const FaultInjection& fault) noexcept {
  if (fault_parameter_error(fault) != nullptr) return false;
  switch (fault.kind) {
    case FaultKind::overcurrent: {
      PlantState state = plant_.state();
      state.i_s_alphabeta_A += fault.surge_A * phase_axis(fault.phase);
      plant_.set_state(state);
      plant_.set_open_phases(plant_.open_phases());  // an open phase carries no surge
      break;
    }
    case FaultKind::overvoltage:
    case FaultKind::undervoltage:
      v_bus_V_ = fault.bus_V;
      break;
    case FaultKind::encoder_loss:
      encoder_frozen_ = true;
      break;
    case FaultKind::adc_stuck:
      adc_stuck_ = true;
      break;
    case FaultKind::phase_loss:
      plant_.set_open_phases(plant_.open_phases() | 1u << fault.phase);
      break;
    case FaultKind::overrun:
      timer_.set_stall_ns(static_cast<uint64_t>(std::llround(fault.stall_us * 1e3)));
      break;
    case FaultKind::can_silence:
      can_.silence();
      break;
  }
  ++injected_count_;
  return true;
}

void SimBoard::repair(const FaultInjection& fault) noexcept {
  switch (fault.kind) {
    case FaultKind::overcurrent:  // a surge: over at once
      break;
    case FaultKind::overvoltage:
    case FaultKind::undervoltage:
      v_bus_V_ = config_.v_bus_V;
      break;
    case FaultKind::encoder_loss:
      // An incremental encoder counts on from where it stopped: the motion meanwhile is lost.
      encoder_offset_counts_ =
          encoder_.count() - encoder_count(plant_.state().theta_mech_rad, config_.encoder_cpr);
      encoder_frozen_ = false;
      break;
    case FaultKind::adc_stuck:
      adc_stuck_ = false;
      break;
    case FaultKind::phase_loss:
      plant_.set_open_phases(plant_.open_phases() & ~(1u << fault.phase));
      break;
    case FaultKind::overrun:
      timer_.set_stall_ns(0);
      break;
    case FaultKind::can_silence:
      can_.unsilence();
      break;
  }
}

}  // namespace imd::sim
