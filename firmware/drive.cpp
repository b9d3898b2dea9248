#include "firmware/drive.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "control/frames.hpp"
#include "control/input_disk.hpp"
#include "control/svpwm.hpp"

namespace imd::firmware {
namespace {

template <typename T>
bool finite(const control::Vec2<T>& v) noexcept {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

/// A duration in whole ticks, rounded up (construction only).
uint64_t ticks(double duration_s, double period_s) noexcept {
  if (!(duration_s > 0)) return 0;
  const double ticks = std::ceil(duration_s / period_s - 1e-9);
  return ticks < 1e18 ? static_cast<uint64_t>(ticks) : UINT64_MAX;  // an infinite duration too
}

}  // namespace

template <typename T>
Drive<T>::Drive(const control::MotorParameters& motor, const DriveConfig& config,
                const DrivePeripherals& peripherals, const ReferenceSource<T>& references,
                const StateOracle<T>* oracle)
    : config_(config),
      limits_(limits(config)),
      hw_(peripherals),
      commanded_(T(config.flux2_ref_Wb2), T(config.stator_flux2_ref_Wb2)),
      references_(config.commands_over_can ? commanded_ : references),
      oracle_(oracle),
      coefficients_(control::discretize_voltage_fed(motor, config.sample_period_s)),
      model_(coefficients_),
      dsmc_(coefficients_, control::DsmcConfig{config.min_flux2_Wb2, config.speed_reaching_pole,
                                               config.flux_reaching_pole}),
      flux_observer_(coefficients_),
      encoder_observer_(coefficients_, {config.encoder_observer_bandwidth_rad_s}),
      load_estimator_(coefficients_,
                      control::place_load_estimator(coefficients_, config.load_estimator_pole,
                                                    config.load_estimator_pole)),
      current_loop_(coefficients_),
      speed_ramp_(config.max_accel_rad_s2, config.sample_period_s),
      iol_stage_(motor, config),
      controller_(config.controller),
      decoder_(config.node_id, {float(config.protection.overspeed_rad_s),
                                float(config.min_flux2_command_Wb2), float(config.max_flux2_Wb2)}),
      telemetry_(config.node_id, peripherals.timer.period_ns(), config.telemetry_rate_Hz),
      encoder_check_({double(peripherals.encoder.counts_per_rev()), config.sample_period_s,
                      motor.J_kgm2, motor.friction_Nms, config.protection.encoder_missing_counts,
                      config.protection.encoder_window_s, config.protection.overspeed_rad_s}),
      adc_stuck_check_(config.protection.adc_stuck_ticks, config.sample_period_s,
                       control::derive_voltage_fed(motor).sigma_H,
                       double(peripherals.adc.scale().phase_A_per_code)),
      phase_loss_check_(config.protection.phase_loss_ratio,
                        config.protection.phase_loss_min_current_A,
                        static_cast<uint32_t>(ticks(config.protection.phase_loss_max_window_s,
                                                    config.sample_period_s))) {
  const control::VoltageFedConstants k = control::derive_voltage_fed(motor);
  sigma_H_ = T(k.sigma_H);
  beta_per_H_ = T(k.beta_per_H);
  pole_pairs_ = T(motor.pole_pairs);
  Lm_H_ = T(motor.Lm_H);
  Ls_H_ = T(motor.Ls_H);
  Lm_over_Lr_ = T(motor.Lm_H / motor.Lr_H);
  a21_ = T(coefficients_.a21);
  a22_ = T(coefficients_.a22);
  b2_ = T(coefficients_.b2);
  torque_per_AWb_ = T(control::kClarkeTorqueFactor * motor.pole_pairs * motor.Lm_H / motor.Lr_H);
  magnetizing_timeout_ticks_ = ticks(config.magnetizing_timeout_s, config.sample_period_s);
  command_timeout_ticks_ = ticks(config.protection.command_timeout_s, config.sample_period_s);
  stop_timeout_ticks_ = ticks(config.stop_timeout_s, config.sample_period_s);
  status_.controller = controller_ == ControllerKind::iol ? 1 : 0;
  hw_.pwm.disable();
  if (config_.adc_calibration_ticks <= 0) {
    const auto scale = hw_.adc.scale();
    for (T& offset : offset_code_) offset = T(scale.phase_mid_code);
    calibrated_ = true;
    machine_.go(DriveState::idle, TransitionReason::calibrated, 0);
    if (config_.auto_enable) enable(0);
  }
  status_.state = machine_.state();
}

template <typename T>
typename Drive<T>::Limits Drive<T>::limits(const DriveConfig& c) noexcept {
  const ProtectionConfig& p = c.protection;
  Limits l;
  l.adc_offset_limit_A = T(c.adc_offset_limit_A);
  l.modulation_margin = T(c.modulation_margin);
  l.current_limit_A = T(c.current_margin * c.i_max_A);
  l.magnetizing_current_A = T(c.magnetizing_current_A);
  l.magnetizing_current_max_A = T(0.9 * c.i_max_A);
  l.magnetized_fraction = T(c.magnetized_fraction);
  l.half_period_s = T(c.sample_period_s / 2);
  l.stop_speed_rad_s = T(c.stop_speed_rad_s);
  l.overcurrent_A = T(p.overcurrent_A);
  l.bus_min_V = T(p.bus_min_V);
  l.bus_max_V = T(p.bus_max_V);
  l.overspeed_rad_s = T(p.overspeed_rad_s);
  l.command_accel_step_rad_s = SpeedRamp<T>::step(c.max_accel_rad_s2, c.sample_period_s);
  l.stop_accel_step_rad_s =
      SpeedRamp<T>::step(std::min(c.max_accel_rad_s2, c.stop_decel_rad_s2), c.sample_period_s);
  l.current_limited = std::isfinite(c.i_max_A);
  return l;
}

template <typename T>
void Drive<T>::pwm_off() noexcept {
  hw_.pwm.disable();
  // Neutral duties: a timer that starts from its last duties applies nothing stale on enable.
  hw_.pwm.set_duties({0.5f, 0.5f, 0.5f});
}

template <typename T>
void Drive<T>::write_line(int line, bool level) noexcept {
  if (hw_.gpio != nullptr && line >= 0) hw_.gpio->write(static_cast<uint8_t>(line), level);
}

template <typename T>
bool Drive<T>::enable_input_active() const noexcept {
  const int line = config_.enable_input_line;
  return hw_.gpio == nullptr || line < 0 || hw_.gpio->read(static_cast<uint8_t>(line));
}

template <typename T>
void Drive<T>::trip(FaultCode code, uint64_t k, uint8_t detail) noexcept {
  pwm_off();
  commanded_.set_speed(T(0));  // after clear and enable, the host sends a new speed
  status_.fault_bits = static_cast<uint16_t>(status_.fault_bits | (1u << unsigned(code)));
  if (machine_.state() == DriveState::fault) return;  // the first fault is kept
  status_.first_fault = code;
  status_.first_fault_tick = k;
  status_.fault_detail = detail;
  machine_.go(DriveState::fault, TransitionReason::fault, k);
  status_.state = DriveState::fault;
  if (hw_.can != nullptr) telemetry_.report_fault(*hw_.can, status_);
}

template <typename T>
bool Drive<T>::modulating() const noexcept {
  const DriveState s = machine_.state();
  return s == DriveState::magnetizing || s == DriveState::running || s == DriveState::stopping;
}

template <typename T>
T Drive<T>::electromagnetic_torque_Nm(const control::RotorFrameState<T>& x) const noexcept {
  return torque_per_AWb_ * control::dot_J<T>(x.i_s_AB_A, x.flux_r_AB_Wb);
}

template <typename T>
bool Drive<T>::calibrate_adc(const hal::AdcSample& sample) noexcept {
  for (int phase = 0; phase < 3; ++phase) calibration_sum_[phase] += sample.phase_code[phase];
  if (++calibration_count_ < config_.adc_calibration_ticks) return false;
  const hal::AdcScale scale = hw_.adc.scale();
  for (int phase = 0; phase < 3; ++phase) {
    offset_code_[phase] = T(calibration_sum_[phase]) / T(calibration_count_);
    const T offset_A = (offset_code_[phase] - T(scale.phase_mid_code)) * T(scale.phase_A_per_code);
    if (std::abs(offset_A) > limits_.adc_offset_limit_A) {
      trip(FaultCode::adc_offset, hw_.timer.tick_count(), uint8_t(phase));
      return false;
    }
  }
  return true;
}

template <typename T>
typename Drive<T>::Estimate Drive<T>::estimate(const hal::AdcSample& sample) noexcept {
  // Encoder: unwrap the free-running counter by differences, keep one revolution.
  const uint32_t count = hw_.encoder.count();
  // 32-bit: the MCU divides those in hardware (cpr <= 2^30, |delta| < 2^31 - 2^30).
  const auto cpr = static_cast<int32_t>(hw_.encoder.counts_per_rev());
  if (!encoder_started_) last_encoder_count_ = count;
  encoder_delta_counts_ = static_cast<int32_t>(count - last_encoder_count_);
  last_encoder_count_ = count;
  encoder_position_ = ((encoder_position_ + encoder_delta_counts_ % cpr) % cpr + cpr) % cpr;
  const T theta_measured_rad = T(2 * std::numbers::pi) * T(encoder_position_) / T(cpr);
  if (!encoder_started_) {  // the first reading sets the angle; speed and load start at rest
    encoder_observer_.reset(theta_measured_rad);
    encoder_started_ = true;
  }
  encoder_observer_.correct(theta_measured_rad);

  Estimate e;
  e.x.theta_mech_rad = encoder_observer_.theta_mech_rad();
  e.x.omega_mech_rad_s = encoder_observer_.omega_mech_rad_s();
  e.x.flux_r_AB_Wb = flux_observer_.flux_r_AB_Wb();
  e.load_Nm = encoder_observer_.load_Nm();
  const hal::AdcScale scale = hw_.adc.scale();
  control::PhaseValues<T> i_abc;
  peak_phase_current_A_ = T(0);
  adc_saturated_ = false;
  for (int phase = 0; phase < 3; ++phase) {
    i_abc[phase] = (T(sample.phase_code[phase]) - offset_code_[phase]) * T(scale.phase_A_per_code);
    peak_phase_current_A_ = std::max(peak_phase_current_A_, std::abs(i_abc[phase]));
    // A code on a rail means the current is beyond what the ADC can measure.
    adc_saturated_ = adc_saturated_ || sample.phase_code[phase] == 0 ||
                     sample.phase_code[phase] >= scale.max_code;
  }
  for (int phase = 0; phase < 3; ++phase) phase_current_A_[phase] = i_abc[phase];
  const Vec2 i_alphabeta = control::clarke(i_abc);
  record_.i_alpha_A = i_alphabeta.x();
  record_.i_beta_A = i_alphabeta.y();
  e.x.i_s_AB_A =
      control::Rotation<T>::from_angle(pole_pairs_ * e.x.theta_mech_rad).apply_inverse(i_alphabeta);

  if (oracle_ != nullptr) {  // ideal sensors: current, speed and position are measured exactly
    const TrueState<T> truth = oracle_->true_state();
    e.x.i_s_AB_A = Vec2(truth.iA_s_A, truth.iB_s_A);
    adc_saturated_ = false;  // the ADC is not used
    const auto true_abc = control::inverse_clarke(
        Vec2(control::Rotation<T>::from_angle(pole_pairs_ * truth.theta_mech_rad)
                 .apply(e.x.i_s_AB_A)));
    peak_phase_current_A_ =
        std::max({std::abs(true_abc[0]), std::abs(true_abc[1]), std::abs(true_abc[2])});
    for (int phase = 0; phase < 3; ++phase) phase_current_A_[phase] = true_abc[phase];
    e.x.omega_mech_rad_s = truth.omega_mech_rad_s;
    e.x.theta_mech_rad = truth.theta_mech_rad;
    if (config_.section_iv_load_estimator) {
      e.load_Nm = load_estimator_.load_Nm();
    } else {
      e.x.flux_r_AB_Wb = Vec2(truth.flux_r_A_Wb, truth.flux_r_B_Wb);
      e.load_Nm = truth.load_Nm;
    }
  }
  return e;
}

template <typename T>
control::Vec2<T> Drive<T>::compensation_AB(const control::RotorFrameState<T>& x) const noexcept {
  return sigma_H_ * pole_pairs_ * x.omega_mech_rad_s *
         control::J_times<T>(x.i_s_AB_A + beta_per_H_ * x.flux_r_AB_Wb);
}

template <typename T>
control::InputDisk<T> Drive<T>::feasible_inputs(const control::RotorFrameState<T>& x,
                                                T v_bus_V) const noexcept {
  control::InputDisk<T> voltage, current;
  if (config_.voltage_limited) {
    voltage = {-compensation_AB(x),
               limits_.modulation_margin * control::svpwm_linear_limit_V(v_bus_V)};
  }
  if (limits_.current_limited) {
    current = {-(a21_ * x.flux_r_AB_Wb + a22_ * x.i_s_AB_A) / b2_, limits_.current_limit_A / b2_};
  }
  return control::inscribed_disk(voltage, current);
}

template <typename T>
control::Vec2<T> Drive<T>::magnetizing_current(const control::RotorFrameState<T>& x,
                                               const Reference<T>& ref) const noexcept {
  // Steady state at zero slip: Phi_r = Lm I and phi_s = Ls I.
  T current_A = limits_.magnetizing_current_A;
  if (!(current_A > T(0))) {
    current_A = controller_ == ControllerKind::iol
                    ? std::sqrt(std::max(ref.stator_flux2_Wb2, T(0))) / Ls_H_
                    : std::sqrt(std::max(ref.flux2_Wb2, T(0))) / Lm_H_;
  }
  if (limits_.current_limited) current_A = std::min(current_A, limits_.magnetizing_current_max_A);
  const T flux = x.flux_r_AB_Wb.norm();
  const Vec2 direction = flux > T(1e-3) ? Vec2(x.flux_r_AB_Wb / flux) : Vec2(T(1), T(0));
  return current_A * direction;
}

template <typename T>
T Drive<T>::magnetized_flux2(const control::RotorFrameState<T>& x) const noexcept {
  if (controller_ != ControllerKind::iol) return x.flux_r_AB_Wb.squaredNorm();
  return (sigma_H_ * x.i_s_AB_A + Lm_over_Lr_ * x.flux_r_AB_Wb).squaredNorm();
}

template <typename T>
T Drive<T>::magnetized_flux2_ref(const Reference<T>& ref) const noexcept {
  return controller_ == ControllerKind::iol ? ref.stator_flux2_Wb2 : ref.flux2_Wb2;
}

template <typename T>
void Drive<T>::protect(uint64_t k, const Estimate& e, const hal::AdcSample& sample,
                       T v_bus_V) noexcept {
  const Limits& p = limits_;
  // In every state: what would harm the inverter or the motor even with the PWM off.
  if (peak_phase_current_A_ > p.overcurrent_A || adc_saturated_) {
    int phase = 0;
    for (int i = 1; i < 3; ++i) {
      if (std::abs(phase_current_A_[i]) > std::abs(phase_current_A_[phase])) phase = i;
    }
    trip(FaultCode::overcurrent, k, uint8_t(phase));
  }
  if (v_bus_V > p.bus_max_V) trip(FaultCode::bus_overvoltage, k);
  if (std::abs(e.x.omega_mech_rad_s) > p.overspeed_rad_s) trip(FaultCode::overspeed, k);
  if (!finite(e.x.flux_r_AB_Wb) || !finite(e.x.i_s_AB_A) || !std::isfinite(e.x.omega_mech_rad_s) ||
      !std::isfinite(e.load_Nm)) {
    trip(FaultCode::non_finite, k);
  }
  const T torque_Nm = modulating() ? electromagnetic_torque_Nm(e.x) : T(0);
  if (oracle_ == nullptr && encoder_check_.failed(encoder_delta_counts_, e.x.omega_mech_rad_s,
                                                  e.load_Nm, torque_Nm, modulating())) {
    trip(FaultCode::encoder, k);
  }
  if (!modulating()) {
    adc_stuck_check_.reset();
    phase_loss_check_.reset();
    return;
  }
  // While the inverter drives the motor.
  if (!(v_bus_V >= p.bus_min_V)) trip(FaultCode::bus_undervoltage, k);  // NaN too
  if (oracle_ == nullptr && adc_stuck_check_.stuck(sample.phase_code, u_written_V_)) {
    trip(FaultCode::adc_stuck, k);
  }
  const T flux_angle_rad =
      pole_pairs_ * e.x.theta_mech_rad + std::atan2(e.x.flux_r_AB_Wb.y(), e.x.flux_r_AB_Wb.x());
  const int lost = phase_loss_check_.lost_phase(phase_current_A_, flux_angle_rad);
  if (lost >= 0) trip(FaultCode::phase_loss, k, uint8_t(lost));
  const DriveState s = machine_.state();
  if (config_.commands_over_can && command_timeout_ticks_ > 0 &&
      (s == DriveState::magnetizing || s == DriveState::running) &&
      k - last_command_tick_ > command_timeout_ticks_) {
    trip(FaultCode::command_timeout, k);
  }
}

template <typename T>
control::Vec2<T> Drive<T>::control(uint64_t k, const Estimate& e, T v_bus_V) noexcept {
  // --- predict over the latency, then choose v~ for the period it will act on.
  const bool latency = config_.pwm_latency_ticks > 0 && config_.compensate_latency;
  const bool stopping = machine_.state() == DriveState::stopping;
  control::RotorFrameState<T> x = e.x;
  if (latency) x = model_.predict(e.x, v_in_flight_V_, e.load_Nm);
  x.theta_mech_rad = control::wrap_pi(x.theta_mech_rad);
  // References at x's step (ref_now) and the step after (ref), the speed through the ramp.
  // Until the drive runs, a limited ramp follows the estimate and an unlimited one the
  // reference, so that the reaching law acts on the real error from the first running tick.
  // Stopping ramps the speed to zero at the stop deceleration.
  auto speed_target = [&](uint64_t tick) {
    return stopping ? T(0) : references_.at_tick(tick).omega_mech_rad_s;
  };
  if (machine_.state() == DriveState::magnetizing) {
    speed_ramp_.reset(speed_ramp_.limited() ? e.x.omega_mech_rad_s : speed_target(k));
  }
  const T ramp_k1 = speed_ramp_.next(speed_ramp_.value(), speed_target(k + 1));
  Reference<T> ref_now = references_.at_tick(k + (latency ? 1 : 0));
  Reference<T> ref = references_.at_tick(k + (latency ? 2 : 1));
  ref_now.omega_mech_rad_s = latency ? ramp_k1 : speed_ramp_.value();
  ref.omega_mech_rad_s = latency ? speed_ramp_.next(ramp_k1, speed_target(k + 2)) : ramp_k1;
  if (stopping) ref_now.torque_Nm = ref.torque_Nm = T(0);
  speed_ramp_.reset(ramp_k1);
  const control::InputDisk<T> feasible = feasible_inputs(x, v_bus_V);
  Vec2 v = Vec2::Zero();
  Vec2 i_command = Vec2::Zero();  // rotor-frame current command (magnetizing, iol)
  if (machine_.state() == DriveState::magnetizing) {
    if (magnetized_flux2(e.x) >= limits_.magnetized_fraction * magnetized_flux2_ref(ref)) {
      machine_.go(DriveState::running, TransitionReason::magnetized, k);
      iol_stage_.start(magnetizing_current(x, ref));
    } else if (k - magnetizing_start_tick_ > magnetizing_timeout_ticks_) {
      trip(FaultCode::magnetizing_timeout, k);
    } else {
      i_command = magnetizing_current(x, ref);
      v = current_loop_.input(x.flux_r_AB_Wb, x.i_s_AB_A, i_command, feasible);
    }
  }
  const DriveState s = machine_.state();
  const bool controlling = s == DriveState::running || s == DriveState::stopping;
  if (controlling && controller_ == ControllerKind::iol) {
    Reference<T> boundary_ref = references_.at_tick(k + uint64_t(iol_stage_.ticks_per_period()));
    boundary_ref.omega_mech_rad_s = ref.omega_mech_rad_s;  // through the speed ramp
    if (stopping) boundary_ref.torque_Nm = T(0);
    const IolTickResult<T> r =
        iol_stage_.tick(e.x.flux_r_AB_Wb, e.x.omega_mech_rad_s, boundary_ref);
    if (r.status != control::IolStatus::ok) trip(FaultCode::singular_control, k);
    i_command = r.i_cmd_AB_A;
    record_.iA_held_A = r.i_held_AB_A.x();
    record_.iB_held_A = r.i_held_AB_A.y();
    v = current_loop_.input(x.flux_r_AB_Wb, x.i_s_AB_A, i_command, feasible);
    record_.iol_boundary = r.boundary;
    if (r.boundary) {
      record_.torque_ref_Nm = r.torque_ref_Nm;
      record_.torque_cmd_Nm = r.torque_cmd_Nm;
      record_.y2 = r.y2;
      record_.y2_ref = r.y2_ref;
      record_.stator_flux2_est_Wb2 = r.flux2_s_Wb2;
      record_.torque_limited = r.torque_limited;
    }
  } else if (controlling) {
    control::DsmcInput<T> in;
    in.flux_r_AB_Wb = x.flux_r_AB_Wb;
    in.i_s_AB_A = x.i_s_AB_A;
    in.omega_mech_rad_s = x.omega_mech_rad_s;
    in.load_Nm = e.load_Nm;
    in.omega_ref_rad_s = ref_now.omega_mech_rad_s;
    in.omega_ref_next_rad_s = ref.omega_mech_rad_s;
    in.flux2_ref_Wb2 = ref_now.flux2_Wb2;
    in.flux2_ref_next_Wb2 = ref.flux2_Wb2;
    in.feasible = feasible;
    const control::DsmcOutput<T> out = dsmc_.step(in);
    if (out.status != control::DsmcStatus::ok) trip(FaultCode::singular_control, k);
    v = out.v_AB_V;
    record_.discriminant = out.discriminant;
    record_.c_k = out.c_k;
    record_.det_B = out.det_B;
    record_.speed_saturated = out.speed_saturated;
    record_.flux_saturated = out.flux_saturated;
  }
  record_.omega_ref_rad_s = ref.omega_mech_rad_s;
  record_.flux2_ref_Wb2 = ref.flux2_Wb2;
  record_.controlled_flux2_ref_Wb2 = magnetized_flux2_ref(ref);

  // --- inner feedback (2) and limits. The held voltage is rotated to the middle of the
  // period it acts on, where the analog law's rotation is on average.
  record_.iA_cmd_A = i_command.x();
  record_.iB_cmd_A = i_command.y();
  if (config_.current_source) {
    if (!finite(i_command)) trip(FaultCode::non_finite, k);
    if (machine_.state() != DriveState::fault && hw_.current_source != nullptr) {
      hw_.current_source->set_current_AB_A(i_command.x(), i_command.y());
      hw_.pwm.enable();
    }
  } else if (config_.analog_inner_loop) {
    if (!finite(v)) trip(FaultCode::non_finite, k);
    if (machine_.state() != DriveState::fault && hw_.analog_inner_loop != nullptr) {
      hw_.analog_inner_loop->set_input_AB_V(v.x(), v.y());
      hw_.pwm.enable();
    }
  } else {
    const Vec2 compensation = compensation_AB(x);
    const auto rotation = control::Rotation<T>::from_angle(
        pole_pairs_ * (x.theta_mech_rad + x.omega_mech_rad_s * limits_.half_period_s));
    const Vec2 u_alphabeta = rotation.apply(compensation + v);
    const control::SvpwmResult<T> pwm = control::svpwm(u_alphabeta, v_bus_V);
    record_.voltage_clipped = pwm.clipped;
    if (pwm.clipped) {  // the observers must see what is actually applied
      const T limit = control::svpwm_linear_limit_V(v_bus_V);
      const T magnitude = u_alphabeta.norm();
      v = rotation.apply_inverse(u_alphabeta * (magnitude > limit ? limit / magnitude : T(1))) -
          compensation;
    }
    record_.u_alpha_V = u_alphabeta.x();
    record_.u_beta_V = u_alphabeta.y();
    if (!finite(u_alphabeta) || !finite(v)) trip(FaultCode::non_finite, k);
    if (machine_.state() != DriveState::fault) {
      hw_.pwm.set_duties({float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])});
      hw_.pwm.enable();
      u_written_V_ = u_alphabeta;
    }
  }
  if (machine_.state() == DriveState::fault) return Vec2::Zero();

  // --- a stop is complete once the ramp is at zero and the motor (nearly) still.
  if (stopping && ((speed_ramp_.value() == T(0) &&
                    std::abs(e.x.omega_mech_rad_s) < limits_.stop_speed_rad_s) ||
                   k - stop_start_tick_ > stop_timeout_ticks_)) {
    pwm_off();
    machine_.go(DriveState::idle, TransitionReason::stopped, k);
    return Vec2::Zero();
  }
  return v;
}

template <typename T>
void Drive<T>::on_tick() noexcept {
  const uint64_t start_ns = hw_.timer.execution_clock_ns();
  write_line(config_.timing_output_line, true);
  const uint64_t k = hw_.timer.tick_count();
  record_.tick = k;
  record_.speed_saturated = record_.flux_saturated = record_.voltage_clipped = false;
  record_.iol_boundary = false;

  const hal::AdcSample sample = hw_.adc.sample();
  enable_input_ = enable_input_active();  // before the commands: enable needs it
  receive_commands(k);
  if (!enable_input_ && modulating()) trip(FaultCode::enable_input, k);
  const T v_bus_V = T(sample.bus_code) * T(hw_.adc.scale().bus_V_per_code);
  if (machine_.state() == DriveState::calibrating) {
    record_.v_bus_V = v_bus_V;
    if (calibrate_adc(sample)) {
      calibrated_ = true;
      machine_.go(DriveState::idle, TransitionReason::calibrated, k);
      if (config_.auto_enable) enable(k + 1);
    }
  } else if (!calibrated_) {
    // A fault before the offsets were known: nothing can be measured; clear_faults
    // calibrates again.
    hw_.pwm.disable();
    record_.v_bus_V = v_bus_V;
  } else {
    // --- sense, estimate, check
    const Estimate e = estimate(sample);
    protect(k, e, sample, v_bus_V);
    Vec2 v = Vec2::Zero();
    if (modulating()) {
      v = control(k, e, v_bus_V);
    } else {
      if (hw_.pwm.enabled()) pwm_off();
      record_.u_alpha_V = record_.u_beta_V = T(0);
      u_written_V_ = Vec2::Zero();
      // Telemetry shows what the drive would aim at once enabled.
      const Reference<T> ref = references_.at_tick(k);
      record_.omega_ref_rad_s = ref.omega_mech_rad_s;
      record_.flux2_ref_Wb2 = ref.flux2_Wb2;
      record_.controlled_flux2_ref_Wb2 = magnetized_flux2_ref(ref);
    }
    if (!hw_.pwm.enabled()) v = Vec2::Zero();

    // --- advance the observers over the period [k, k+1] with the input acting on it.
    const Vec2 acting = config_.pwm_latency_ticks > 0 ? v_in_flight_V_ : v;
    flux_observer_.update(e.x.i_s_AB_A, acting);
    encoder_observer_.predict(e.x.i_s_AB_A, e.x.flux_r_AB_Wb, acting);
    load_estimator_.update(e.x.omega_mech_rad_s, e.x.i_s_AB_A, e.x.flux_r_AB_Wb, acting);
    v_in_flight_V_ = v;

    record_.omega_est_rad_s = e.x.omega_mech_rad_s;
    record_.theta_est_rad = e.x.theta_mech_rad;
    record_.flux_est_A_Wb = e.x.flux_r_AB_Wb.x();
    record_.flux_est_B_Wb = e.x.flux_r_AB_Wb.y();
    record_.flux2_est_Wb2 = e.x.flux_r_AB_Wb.squaredNorm();
    record_.controlled_flux2_Wb2 = magnetized_flux2(e.x);
    record_.load_est_Nm = e.load_Nm;
    record_.iA_A = e.x.i_s_AB_A.x();
    record_.iB_A = e.x.i_s_AB_A.y();
    record_.v_bus_V = v_bus_V;
    record_.v_A_V = v.x();
    record_.v_B_V = v.y();
  }
  const uint64_t exec_ns = hw_.timer.execution_clock_ns() - start_ns;
  record_.exec_ns = static_cast<uint32_t>(std::min<uint64_t>(exec_ns, UINT32_MAX));
  execution_.add(record_.exec_ns);
  const uint32_t budget_ns = config_.protection.tick_budget_ns;
  if (budget_ns > 0 && record_.exec_ns > budget_ns) {
    ++execution_.overruns;
    trip(FaultCode::overrun, k);  // the PWM is off before the next period starts
    v_in_flight_V_ = Vec2::Zero();  // so this tick's voltage never acts
  }
  status_.state = machine_.state();
  status_.command_counter = decoder_.last_counter();
  status_.rejected_commands = decoder_.rejected_total();
  record_.state = status_.state;
  record_.fault = status_.first_fault;
  record_.fault_bits = status_.fault_bits;
  if (hw_.can != nullptr) {
    status_.can_bus_off = hw_.can->bus_off();
    telemetry_.publish(k, *hw_.can, record_, status_, machine_, execution_, budget_ns);
  }
  const bool faulted = status_.state == DriveState::fault;
  if (faulted != fault_line_level_) {
    write_line(config_.fault_output_line, faulted);  // on change only: a system call on Linux
    fault_line_level_ = faulted;
  }
  write_line(config_.timing_output_line, false);
}

template <typename T>
void Drive<T>::shut_down(uint64_t k) noexcept {
  pwm_off();
  if (modulating()) machine_.go(DriveState::idle, TransitionReason::shutdown, k);
  status_.state = machine_.state();
  record_.state = status_.state;
  if (hw_.can != nullptr) telemetry_.final_heartbeat(*hw_.can, status_, machine_);
  write_line(config_.timing_output_line, false);
}

template class Drive<float>;
template class Drive<double>;

}  // namespace imd::firmware
