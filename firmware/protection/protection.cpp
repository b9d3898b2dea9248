#include "firmware/protection/protection.hpp"

#include <cmath>
#include <numbers>

#include "control/encoder_observer.hpp"
#include "control/svpwm.hpp"
#include "control/voltage_fed_model.hpp"

#include "firmware/duration_ticks.hpp"
#include "firmware/protection/magnetizing_timeout.hpp"

namespace imd::firmware {
namespace {

/// A tick count in 32 bits: beyond 2^32 - 1 ticks (5 days at 10 kHz), no timeout.
uint32_t saturated(uint64_t ticks) noexcept {
  return ticks < UINT32_MAX ? static_cast<uint32_t>(ticks) : UINT32_MAX;
}

/// The encoder check's configuration, with the estimates' quantization errors of the encoder
/// observer the drive runs (construction only).
template <typename T>
typename EncoderCheck<T>::Config encoder_config(const control::MotorParameters& motor,
                                                const control::VoltageFedCoefficients& c,
                                                const DriveConfig& config, Real counts_per_rev) {
  // In the drive's arithmetic: on the MCU the bound's few thousand steps are float, not soft
  // double (control/encoder_observer.hpp raises the float result by a rounding margin).
  const control::QuantizationErrorBounds q =
      control::encoder_quantization_bounds<T>(c, T(config.encoder_observer_bandwidth_rad_s),
                                              T(2 * std::numbers::pi_v<Real> / counts_per_rev));
  return {counts_per_rev,
          config.sample_period_s,
          motor.J_kgm2,
          motor.friction_Nms,
          config.protection.encoder_missing_counts,
          config.protection.overspeed_rad_s,
          q.omega_rad_s,
          config.encoder_observer_bandwidth_rad_s};
}

/// The phase-loss check's rules (docs/safety.md), from the motor's leakage inductance and
/// transient time constant, the board's voltage error and ADC noise, and the sample period.
template <typename T>
typename PhaseLossCheck<T>::Config phase_loss_config(const control::MotorParameters& motor,
                                                     const DriveConfig& config,
                                                     Real adc_A_per_code) {
  const control::VoltageFedConstants k = control::derive_voltage_fed(motor);
  const Real period_s = config.sample_period_s;
  // A window of the transient time constant sigma / (Rs + Rr Lm^2/Lr^2) = 1/gamma: the time
  // the current takes to follow the voltage; at least 4 ticks.
  const Real window = std::max(std::ceil(1 / (k.gamma_per_s * period_s)), Real(4));
  // The mean of (|i_pred| - |i|) over the window: per tick its noise is at most
  // sqrt(2) sigma_adc; six standard deviations of the window's mean.
  const Real noise_A = config.protection.adc_noise_codes * adc_A_per_code;
  typename PhaseLossCheck<T>::Config c;
  c.window_ticks = static_cast<uint32_t>(window);
  c.missing_A_per_bus_V =
      config.protection.inverter_voltage_error_share / std::sqrt(Real(3.0)) * period_s / k.sigma_H;
  c.noise_floor_A = 6 * std::sqrt(Real(2.0)) * noise_A / std::sqrt(window);
  // An open phase reads the noise alone: its mean |i| is 0.8 n (the mean of |N(0, n)|), and a
  // window's mean lies within a few 0.6 n / sqrt(N) of that; 3 n leaves room for a board
  // noisier than its setting, and two codes for the offset left after calibration or drifted
  // since (a quiet converter's setting may be under a code).
  c.open_mean_A = 3 * noise_A + 2 * adc_A_per_code;
  return c;
}

}  // namespace

template <typename T>
MotorChecks<T>::MotorChecks(const control::MotorParameters& motor,
                            const control::VoltageFedCoefficients& c, const DriveConfig& config,
                            Real counts_per_rev, Real adc_A_per_code) noexcept
    : pole_pairs(T(motor.pole_pairs)),
      torque_per_AWb(
          T(control::kClarkeTorqueFactor * Real(motor.pole_pairs) * motor.Lm_H / motor.Lr_H)),
      max_load_share(T(config.protection.encoder_max_load_share)),
      torque_limit_Nm(T(config.torque_limit_Nm)),
      current_limit_A(T(config.current_margin * config.i_max_A)),
      per_Lm_H(T(1 / motor.Lm_H)),
      magnetizing_timeout_ticks(
          saturated(duration_ticks(magnetizing_timeout_s(motor, config), config.sample_period_s))),
      encoder(encoder_config<T>(motor, c, config, counts_per_rev)),
      adc_stuck(config.protection.adc_stuck_ticks, adc_A_per_code,
                control::derive_voltage_fed(motor).sigma_H, config.sample_period_s),
      phase_loss(phase_loss_config<T>(motor, config, adc_A_per_code)),
      law_failure(
          2 * std::max(phase_loss.window_ticks(),
                       static_cast<uint32_t>(std::max(config.protection.adc_stuck_ticks, 1)))) {}

template <typename T>
Protection<T>::Protection(const DriveConfig& config) noexcept
    : config_(config.protection),
      commands_over_can_(config.commands_over_can),
      overcurrent_A_(T(config.protection.overcurrent_A)),
      bus_min_V_(T(config.protection.bus_min_V)),
      bus_max_V_(T(config.protection.bus_max_V)),
      overspeed_rad_s_(T(config.protection.overspeed_rad_s)),
      command_timeout_ticks_(
          saturated(duration_ticks(config.protection.command_timeout_s, config.sample_period_s))) {}

template <typename T>
void Protection<T>::set_clock(uint32_t clock_Hz) noexcept {
  const Real counts = Real(config_.tick_budget_ns) * Real(1e-9) * Real(clock_Hz);
  // Rounded by a 32-bit conversion: a float's 64-bit one (llround) is soft double on the MCU.
  budget_counts_ = counts < Real(4e9) ? static_cast<uint32_t>(counts + Real(0.5)) : UINT32_MAX;
}

template <typename T>
Trip Protection<T>::check(const Measurement<T>& m, const Estimate<T>& e, const SupervisedState& s,
                          const LawOutput<T>& law, const Modulation<T>& out,
                          MotorChecks<T>* motor) noexcept {
  Trip trip;
  if (s.restarted && motor != nullptr) motor->reset();
  if (!s.enable_input && s.modulating) trip.add(FaultCode::enable_input);
  if (m.calibration == Calibration::offset_fault) {
    trip.add(FaultCode::adc_offset, m.offset_fault_phase);
  }
  if (!m.valid) return trip;  // nothing measured: calibrating, or offsets unknown
  check_sensed(m, e, s.modulating && !s.brake_may_hold, s.dc_braking ? nullptr : motor, trip);
  if (!s.modulating || motor == nullptr || trip.any()) {
    if (motor != nullptr) motor->idle();
    return trip;
  }
  check_driving(m, e, s, *motor, trip);
  if (trip.any()) return trip;
  if (s.magnetizing && s.magnetizing_ticks > motor->magnetizing_timeout_ticks) {
    trip.add(FaultCode::magnetizing_timeout);
    return trip;
  }
  if (motor->law_failure.failed(law.ok)) trip.add(FaultCode::singular_control);
  if (!out.finite) trip.add(FaultCode::non_finite);
  return trip;
}

template <typename T>
inline void Protection<T>::check_sensed(const Measurement<T>& m, const Estimate<T>& e,
                                        bool modulating, MotorChecks<T>* motor,
                                        Trip& trip) noexcept {
  if (m.i_peak_A > overcurrent_A_ || m.adc_saturated) {
    int phase = 0;
    for (int i = 1; i < 3; ++i) {
      if (std::abs(m.i_abc_A[i]) > std::abs(m.i_abc_A[phase])) phase = i;
    }
    trip.add(FaultCode::overcurrent, uint8_t(phase));
  }
  if (m.v_bus_V > bus_max_V_) trip.add(FaultCode::bus_overvoltage);
  if (std::abs(e.x.omega_mech_rad_s) > overspeed_rad_s_) trip.add(FaultCode::overspeed);
  if (!control::all_finite(e.x.flux_r_AB_Wb.x(), e.x.flux_r_AB_Wb.y(), e.x.i_s_AB_A.x(),
                           e.x.i_s_AB_A.y(), e.x.omega_mech_rad_s, e.load_Nm)) {
    trip.add(FaultCode::non_finite);
  }
  if (motor == nullptr) return;  // no motion model to judge the encoder by
  const bool driving = modulating && !trip.any();  // a fault has turned the PWM off
  const T torque_Nm =
      driving ? motor->torque_per_AWb * control::dot_J<T>(e.x.i_s_AB_A, e.x.flux_r_AB_Wb) : T(0);
  if (config_.check_encoder &&
      motor->encoder.failed(m.encoder_delta_counts, e.x.omega_mech_rad_s, torque_Nm,
                            motor->max_load_Nm(e.x.flux_r_AB_Wb.squaredNorm()), driving)) {
    trip.add(FaultCode::encoder);
  }
}

template <typename T>
inline void Protection<T>::check_driving(const Measurement<T>& m, const Estimate<T>& e,
                                         const SupervisedState& s,
                                         MotorChecks<T>& motor, Trip& trip) noexcept {
  if (!(m.v_bus_V >= bus_min_V_)) trip.add(FaultCode::bus_undervoltage);  // NaN too
  // The model's prediction rests on the estimate, of no use while DC braking (the encoder
  // failed): the stuck check then gathers no evidence, as the phase-loss check does not judge.
  if (config_.check_adc_stuck &&
      motor.adc_stuck.stuck(m.phase_code, m.i_abc_A, m.v_bus_V, e.i_predicted_alphabeta_A,
                            e.current_predicted && !s.dc_braking)) {
    trip.add(FaultCode::adc_stuck);
  }
  // Codes that repeat exactly (a stuck ADC, before its own check has the evidence to say so)
  // read as a current that stopped following the model: not a phase's verdict to give, for
  // one stuck-ADC window at most (an open phase under a still voltage and a quiet ADC freezes
  // the codes too, and must still be found).
  const bool frozen = config_.check_adc_stuck && motor.adc_stuck.deferring();
  if (e.current_predicted && !s.dc_braking && !frozen) {
    const control::PhaseValues<T> predicted = control::inverse_clarke(e.i_predicted_alphabeta_A);
    const T i_predicted_abc_A[3] = {predicted[0], predicted[1], predicted[2]};
    const int lost = motor.phase_loss.lost_phase(i_predicted_abc_A, m.i_abc_A, m.v_bus_V);
    if (lost >= 0) trip.add(FaultCode::phase_loss, uint8_t(lost));
  }
  if (commands_over_can_ && command_timeout_ticks_ > 0 && s.watchdog_armed &&
      s.command_silence_ticks > command_timeout_ticks_) {
    trip.add(FaultCode::command_timeout);
  }
}

template <typename T>
Trip Protection<T>::over_budget(uint32_t exec_counts) const noexcept {
  Trip trip;
  if (budget_counts_ > 0 && exec_counts > budget_counts_) trip.add(FaultCode::overrun);
  return trip;
}

template struct MotorChecks<float>;
template struct MotorChecks<double>;
template class Protection<float>;
template class Protection<double>;

}  // namespace imd::firmware
