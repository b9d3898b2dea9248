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

}  // namespace

template <typename T>
Drive<T>::Drive(const control::MotorParameters& motor, const DriveConfig& config,
                const DrivePeripherals& peripherals, const ReferenceSource& references,
                const StateOracle* oracle)
    : config_(config),
      hw_(peripherals),
      references_(references),
      oracle_(oracle),
      coefficients_(control::discretize_seed000(motor, config.sample_period_s)),
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
      iol_stage_(motor, config) {
  const control::Seed000Constants k = control::derive_seed000(motor);
  sigma_H_ = T(k.sigma_H);
  beta_per_H_ = T(k.beta_per_H);
  pole_pairs_ = T(motor.pole_pairs);
  Lm_H_ = T(motor.Lm_H);
  Ls_H_ = T(motor.Ls_H);
  Lm_over_Lr_ = T(motor.Lm_H / motor.Lr_H);
  a21_ = T(coefficients_.a21);
  a22_ = T(coefficients_.a22);
  b2_ = T(coefficients_.b2);
  hw_.pwm.disable();
  if (config_.adc_calibration_ticks <= 0) {
    const auto scale = hw_.adc.scale();
    for (T& offset : offset_code_) offset = T(scale.phase_mid_code);
    state_ = DriveState::magnetizing;
  }
}

template <typename T>
void Drive<T>::trip(FaultCode code) noexcept {
  hw_.pwm.disable();
  if (state_ != DriveState::fault) fault_ = code;  // the first fault is kept
  state_ = DriveState::fault;
}

template <typename T>
bool Drive<T>::calibrate_adc(const hal::AdcSample& sample) noexcept {
  for (int phase = 0; phase < 3; ++phase) calibration_sum_[phase] += sample.phase_code[phase];
  if (++calibration_count_ < config_.adc_calibration_ticks) return false;
  const hal::AdcScale scale = hw_.adc.scale();
  for (int phase = 0; phase < 3; ++phase) {
    offset_code_[phase] = T(calibration_sum_[phase]) / T(calibration_count_);
    const T offset_A = (offset_code_[phase] - T(scale.phase_mid_code)) * T(scale.phase_A_per_code);
    if (std::abs(offset_A) > T(config_.adc_offset_limit_A)) {
      trip(FaultCode::adc_offset);
      return false;
    }
  }
  return true;
}

template <typename T>
typename Drive<T>::Estimate Drive<T>::estimate(const hal::AdcSample& sample) noexcept {
  // Encoder: unwrap the free-running counter by differences, keep one revolution.
  const uint32_t count = hw_.encoder.count();
  const int64_t cpr = hw_.encoder.counts_per_rev();
  if (!encoder_started_) last_encoder_count_ = count;
  encoder_position_ += static_cast<int32_t>(count - last_encoder_count_);
  last_encoder_count_ = count;
  encoder_position_ = ((encoder_position_ % cpr) + cpr) % cpr;
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
  const Vec2 i_alphabeta = control::clarke(i_abc);
  record_.i_alpha_A = double(i_alphabeta.x());
  record_.i_beta_A = double(i_alphabeta.y());
  e.x.i_s_AB_A =
      control::Rotation<T>::from_angle(pole_pairs_ * e.x.theta_mech_rad).apply_inverse(i_alphabeta);

  if (oracle_ != nullptr) {  // ideal sensors: current, speed and position are measured exactly
    const TrueState truth = oracle_->true_state();
    e.x.i_s_AB_A = Vec2(T(truth.i_s_A_A), T(truth.i_s_B_A));
    adc_saturated_ = false;  // the ADC is not used
    const auto true_abc = control::inverse_clarke(
        Vec2(control::Rotation<T>::from_angle(pole_pairs_ * T(truth.theta_mech_rad))
                 .apply(e.x.i_s_AB_A)));
    peak_phase_current_A_ =
        std::max({std::abs(true_abc[0]), std::abs(true_abc[1]), std::abs(true_abc[2])});
    e.x.omega_mech_rad_s = T(truth.omega_mech_rad_s);
    e.x.theta_mech_rad = T(truth.theta_mech_rad);
    if (config_.section_iv_load_estimator) {
      e.load_Nm = load_estimator_.load_Nm();
    } else {
      e.x.flux_r_AB_Wb = Vec2(T(truth.flux_r_A_Wb), T(truth.flux_r_B_Wb));
      e.load_Nm = T(truth.load_Nm);
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
               T(config_.modulation_margin) * control::svpwm_linear_limit_V(v_bus_V)};
  }
  if (std::isfinite(config_.i_max_A)) {
    current = {-(a21_ * x.flux_r_AB_Wb + a22_ * x.i_s_AB_A) / b2_,
               T(config_.current_margin * config_.i_max_A) / b2_};
  }
  return control::inscribed_disk(voltage, current);
}

template <typename T>
control::Vec2<T> Drive<T>::magnetizing_current(const control::RotorFrameState<T>& x,
                                               const Reference& ref) const noexcept {
  // Steady state at zero slip: Phi_r = Lm I and phi_s = Ls I.
  T current_A = T(config_.magnetizing_current_A);
  if (!(current_A > T(0))) {
    current_A = config_.controller == ControllerKind::iol
                    ? std::sqrt(std::max(T(ref.stator_flux2_Wb2), T(0))) / Ls_H_
                    : std::sqrt(std::max(T(ref.flux2_Wb2), T(0))) / Lm_H_;
  }
  if (std::isfinite(config_.i_max_A)) current_A = std::min(current_A, T(0.9 * config_.i_max_A));
  const T flux = x.flux_r_AB_Wb.norm();
  const Vec2 direction = flux > T(1e-3) ? Vec2(x.flux_r_AB_Wb / flux) : Vec2(T(1), T(0));
  return current_A * direction;
}

template <typename T>
T Drive<T>::magnetized_flux2(const control::RotorFrameState<T>& x) const noexcept {
  if (config_.controller != ControllerKind::iol) return x.flux_r_AB_Wb.squaredNorm();
  return (sigma_H_ * x.i_s_AB_A + Lm_over_Lr_ * x.flux_r_AB_Wb).squaredNorm();
}

template <typename T>
T Drive<T>::magnetized_flux2_ref(const Reference& ref) const noexcept {
  return T(config_.controller == ControllerKind::iol ? ref.stator_flux2_Wb2 : ref.flux2_Wb2);
}

template <typename T>
void Drive<T>::on_tick() noexcept {
  const uint64_t start_ns = hw_.timer.execution_clock_ns();
  const uint64_t k = hw_.timer.tick_count();
  record_.tick = k;
  record_.speed_saturated = record_.flux_saturated = record_.voltage_clipped = false;
  record_.iol_boundary = false;

  const hal::AdcSample sample = hw_.adc.sample();
  if (state_ == DriveState::fault) {
    hw_.pwm.disable();
  } else if (state_ == DriveState::calibrating) {
    if (calibrate_adc(sample)) {
      state_ = DriveState::magnetizing;
      magnetizing_start_tick_ = k + 1;
    }
  } else {
    // --- sense and estimate
    const T v_bus_V = T(sample.bus_code) * T(hw_.adc.scale().bus_V_per_code);
    const Estimate e = estimate(sample);
    if (peak_phase_current_A_ > T(config_.overcurrent_trip_A) || adc_saturated_) {
      trip(FaultCode::overcurrent);
    }
    if (!(v_bus_V >= T(config_.bus_min_V))) trip(FaultCode::bus_undervoltage);  // NaN too
    if (v_bus_V > T(config_.bus_max_V)) trip(FaultCode::bus_overvoltage);
    // --- control: predict over the latency, then choose v~ for the period it will act on.
    const bool latency = config_.pwm_latency_ticks > 0 && config_.compensate_latency;
    control::RotorFrameState<T> x = e.x;
    if (latency) x = model_.predict(e.x, v_in_flight_V_, e.load_Nm);
    x.theta_mech_rad = control::wrap_pi(x.theta_mech_rad);
    // References at x's step (ref_now) and the step after (ref), the speed through the ramp.
    // Until the drive runs, a limited ramp follows the estimate and an unlimited one the
    // reference, so that the reaching law acts on the real error from the first running tick.
    if (state_ != DriveState::running) {
      speed_ramp_.reset(speed_ramp_.limited() ? e.x.omega_mech_rad_s
                                              : T(references_.at_tick(k).omega_mech_rad_s));
    }
    const T ramp_k1 =
        speed_ramp_.next(speed_ramp_.value(), T(references_.at_tick(k + 1).omega_mech_rad_s));
    Reference ref_now = references_.at_tick(k + (latency ? 1 : 0));
    Reference ref = references_.at_tick(k + (latency ? 2 : 1));
    ref_now.omega_mech_rad_s = double(latency ? ramp_k1 : speed_ramp_.value());
    ref.omega_mech_rad_s =
        double(latency ? speed_ramp_.next(ramp_k1, T(ref.omega_mech_rad_s)) : ramp_k1);
    speed_ramp_.reset(ramp_k1);
    const control::InputDisk<T> feasible = feasible_inputs(x, v_bus_V);
    Vec2 v = Vec2::Zero();
    Vec2 i_command = Vec2::Zero();  // rotor-frame current command (magnetizing, iol)
    if (state_ == DriveState::magnetizing) {
      if (magnetized_flux2(e.x) >= T(config_.magnetized_fraction) * magnetized_flux2_ref(ref)) {
        state_ = DriveState::running;
        iol_stage_.start(magnetizing_current(x, ref));
      } else if (double(k - magnetizing_start_tick_) * config_.sample_period_s >
                 config_.magnetizing_timeout_s) {
        trip(FaultCode::magnetizing_timeout);
      } else {
        i_command = magnetizing_current(x, ref);
        v = current_loop_.input(x.flux_r_AB_Wb, x.i_s_AB_A, i_command, feasible);
      }
    }
    if (state_ == DriveState::running && config_.controller == ControllerKind::iol) {
      Reference boundary_ref = references_.at_tick(k + uint64_t(iol_stage_.ticks_per_period()));
      boundary_ref.omega_mech_rad_s = ref.omega_mech_rad_s;  // through the speed ramp
      const IolTickResult<T> r =
          iol_stage_.tick(e.x.flux_r_AB_Wb, e.x.omega_mech_rad_s, boundary_ref);
      if (r.status != control::IolStatus::ok) trip(FaultCode::singular_control);
      i_command = r.i_cmd_AB_A;
      record_.i_held_A_A = double(r.i_held_AB_A.x());
      record_.i_held_B_A = double(r.i_held_AB_A.y());
      v = current_loop_.input(x.flux_r_AB_Wb, x.i_s_AB_A, i_command, feasible);
      record_.iol_boundary = r.boundary;
      if (r.boundary) {
        record_.torque_ref_Nm = double(r.torque_ref_Nm);
        record_.torque_cmd_Nm = double(r.torque_cmd_Nm);
        record_.y2 = double(r.y2);
        record_.y2_ref = double(r.y2_ref);
        record_.stator_flux2_est_Wb2 = double(r.flux2_s_Wb2);
        record_.torque_limited = r.torque_limited;
      }
    } else if (state_ == DriveState::running) {
      control::DsmcInput<T> in;
      in.flux_r_AB_Wb = x.flux_r_AB_Wb;
      in.i_s_AB_A = x.i_s_AB_A;
      in.omega_mech_rad_s = x.omega_mech_rad_s;
      in.load_Nm = e.load_Nm;
      in.omega_ref_rad_s = T(ref_now.omega_mech_rad_s);
      in.omega_ref_next_rad_s = T(ref.omega_mech_rad_s);
      in.flux2_ref_Wb2 = T(ref_now.flux2_Wb2);
      in.flux2_ref_next_Wb2 = T(ref.flux2_Wb2);
      in.feasible = feasible;
      const control::DsmcOutput<T> out = dsmc_.step(in);
      if (out.status != control::DsmcStatus::ok) trip(FaultCode::singular_control);
      v = out.v_AB_V;
      record_.discriminant = double(out.discriminant);
      record_.c_k = double(out.c_k);
      record_.det_B = double(out.det_B);
      record_.speed_saturated = out.speed_saturated;
      record_.flux_saturated = out.flux_saturated;
    }
    record_.omega_ref_rad_s = ref.omega_mech_rad_s;
    record_.flux2_ref_Wb2 = ref.flux2_Wb2;

    // --- inner feedback (2) and limits. The held voltage is rotated to the middle of the
    // period it acts on, where the analog law's rotation is on average.
    record_.i_cmd_A_A = double(i_command.x());
    record_.i_cmd_B_A = double(i_command.y());
    if (config_.current_source) {
      if (!finite(i_command)) trip(FaultCode::non_finite);
      if (state_ != DriveState::fault && hw_.current_source != nullptr) {
        hw_.current_source->set_current_AB_A(double(i_command.x()), double(i_command.y()));
        hw_.pwm.enable();
      }
    } else if (config_.analog_inner_loop) {
      if (!finite(v)) trip(FaultCode::non_finite);
      if (state_ != DriveState::fault && hw_.analog_inner_loop != nullptr) {
        hw_.analog_inner_loop->set_input_AB_V(double(v.x()), double(v.y()));
        hw_.pwm.enable();
      }
    } else {
      const Vec2 compensation = compensation_AB(x);
      const auto rotation = control::Rotation<T>::from_angle(
          pole_pairs_ * (x.theta_mech_rad + x.omega_mech_rad_s * T(config_.sample_period_s / 2)));
      const Vec2 u_alphabeta = rotation.apply(compensation + v);
      const control::SvpwmResult<T> pwm = control::svpwm(u_alphabeta, v_bus_V);
      record_.voltage_clipped = pwm.clipped;
      if (pwm.clipped) {  // the observers must see what is actually applied
        const T limit = control::svpwm_linear_limit_V(v_bus_V);
        const T magnitude = u_alphabeta.norm();
        v = rotation.apply_inverse(u_alphabeta * (magnitude > limit ? limit / magnitude : T(1))) -
            compensation;
      }
      record_.u_alpha_V = double(u_alphabeta.x());
      record_.u_beta_V = double(u_alphabeta.y());
      if (!finite(u_alphabeta) || !finite(v)) trip(FaultCode::non_finite);
      if (state_ != DriveState::fault) {
        hw_.pwm.set_duties({float(pwm.duty[0]), float(pwm.duty[1]), float(pwm.duty[2])});
        hw_.pwm.enable();
      }
    }
    if (state_ == DriveState::fault) v = Vec2::Zero();

    // --- advance the observers over the period [k, k+1] with the input acting on it.
    const Vec2 acting = config_.pwm_latency_ticks > 0 ? v_in_flight_V_ : v;
    flux_observer_.update(e.x.i_s_AB_A, acting);
    encoder_observer_.predict(e.x.i_s_AB_A, e.x.flux_r_AB_Wb, acting);
    load_estimator_.update(e.x.omega_mech_rad_s, e.x.i_s_AB_A, e.x.flux_r_AB_Wb, acting);
    v_in_flight_V_ = v;

    record_.omega_est_rad_s = double(e.x.omega_mech_rad_s);
    record_.theta_est_rad = double(e.x.theta_mech_rad);
    record_.flux_est_A_Wb = double(e.x.flux_r_AB_Wb.x());
    record_.flux_est_B_Wb = double(e.x.flux_r_AB_Wb.y());
    record_.flux2_est_Wb2 = double(e.x.flux_r_AB_Wb.squaredNorm());
    record_.load_est_Nm = double(e.load_Nm);
    record_.v_bus_V = double(v_bus_V);
    record_.v_A_V = double(v.x());
    record_.v_B_V = double(v.y());
  }
  record_.state = state_;
  record_.fault = fault_;
  const uint64_t exec_ns = hw_.timer.execution_clock_ns() - start_ns;
  record_.exec_ns = static_cast<uint32_t>(std::min<uint64_t>(exec_ns, UINT32_MAX));
  execution_.add(record_.exec_ns);
  if (config_.tick_budget_ns > 0 && record_.exec_ns > config_.tick_budget_ns) {
    ++execution_.overruns;
    trip(FaultCode::overrun);  // the PWM is off before the next period starts
    record_.state = state_;
    record_.fault = fault_;
  }
}

template class Drive<float>;
template class Drive<double>;

}  // namespace imd::firmware
