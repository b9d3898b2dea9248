#pragma once
/// The gains of the indirect field-oriented controller (control/ifoc.hpp), from the motor
/// parameters, the sample period and the speed-feedback bandwidth by the rules of docs/ifoc.md:
///
/// * Current loops. After the cross-coupling and back-EMF feed-forward each axis of the
///   rotor-flux frame is sigma di/dt = -sigma gamma i + u, whose zero-order-hold model is
///   i(k+1) = a i(k) + b u(k), a = e^{-gamma T}, b = (1 - a) / (sigma gamma). The PI
///   C(z) = Kp (z - a) / (z - 1) cancels the plant's pole (the stator transient time constant
///   1/gamma) and leaves one closed-loop pole at z = 1 - Kp b. Placing it at e^{-w_c T}:
///   Kp = (1 - e^{-w_c T}) / b, integral gain per sample Ki = Kp (1 - a).
///   Default w_c = 2 pi f_s / 20 (f_s / 20, 500 Hz at 10 kHz): the half period of the
///   zero-order hold then costs w_c T / 2 = 9 degrees of phase at the crossover.
/// * Speed loop: Kp = J w_s, integral zero at w_s / 4 (control/speed_pi.hpp), with
///   w_s = min(w_c / 10, w_obs / 4): a decade below the current loop (the inner loop looks like
///   unity to it), and a factor 4 below the speed feedback's bandwidth (14 degrees of phase).
/// Construction only (in Real: control/real.hpp).
#include <limits>
#include <numbers>

#include "control/field_weakening.hpp"
#include "control/motor_parameters.hpp"
#include "control/speed_pi.hpp"

namespace imd::control {

struct IfocSpec {
  Real sample_period_s = Real(1e-4);
  Real current_bandwidth_rad_s = 0.0;           ///< 0: f_s / 20 in rad/s
  Real speed_bandwidth_rad_s = 0.0;             ///< 0: min(w_c / 10, w_obs / 4)
  Real speed_feedback_bandwidth_rad_s = 400.0;  ///< w_obs: the speed estimate's bandwidth
  Real torque_limit_Nm = 240.0;
  Real current_limit_A =
      std::numeric_limits<Real>::max();  ///< |i| the law plans for (the other laws' margin applied)
  /// Share of the voltage disk the steady state may use in field weakening; the rest is left
  /// to the current loops' transients (control/field_weakening.hpp).
  Real field_weakening_voltage_share = kFieldWeakeningVoltageShare;
  Real min_flux_Wb = Real(0.03);  ///< floor of the flux the slip and the torque divide by
  int latency_ticks = 1;      ///< the angle is advanced to the period the voltage acts on
};

struct IfocGains {
  Real sample_period_s = 0.0;
  Real current_bandwidth_rad_s = 0.0, speed_bandwidth_rad_s = 0.0;
  Real current_kp_V_per_A = 0.0;  ///< proportional gain
  Real current_ki_V_per_A = 0.0;  ///< integral gain per sample
  Real current_pole = 0.0;        ///< e^{-w_c T}: the designed closed-loop pole
  SpeedPiConfig speed;
  // The model the controller holds (its own rotor time constant: a mismatch shows here).
  Real sigma_H = 0.0;           ///< sigma Ls, the transient inductance
  Real gamma_per_s = 0.0;       ///< 1 / stator transient time constant
  Real rotor_flux_decay = 0.0;  ///< e^{-T Rr/Lr}
  Real alpha_per_s = 0.0;       ///< Rr / Lr
  Real Lm_H = 0.0, Ls_H = 0.0, Rs_Ohm = 0.0;
  Real Lm_over_Lr = 0.0;
  Real torque_constant_Nm_per_Wb_A = 0.0;  ///< 3/2 p Lm / Lr: T = this psi_r i_q
  int pole_pairs = 1;
  Real J_kgm2 = 0.0, friction_Nms = 0.0;
  Real torque_limit_Nm = 0.0, current_limit_A = 0.0;
  Real field_weakening_voltage_share = kFieldWeakeningVoltageShare;
  Real min_flux_Wb = Real(0.03);
  int latency_ticks = 1;
};

/// The rules' bandwidths (also the DSMC's torque channel's, docs/control.md): the current loop
/// at f_s / 20 in rad/s; the speed loop at min(w_c / 10, w_obs / 4). Construction only.
constexpr Real default_current_bandwidth_rad_s(Real sample_period_s) noexcept {
  return 2 * std::numbers::pi_v<Real> / (20 * sample_period_s);
}
constexpr Real default_speed_bandwidth_rad_s(Real current_bandwidth_rad_s,
                                             Real speed_feedback_bandwidth_rad_s) noexcept {
  return current_bandwidth_rad_s / 10 < speed_feedback_bandwidth_rad_s / 4
             ? current_bandwidth_rad_s / 10
             : speed_feedback_bandwidth_rad_s / 4;
}

/// The gains for a valid motor and spec (sample period > 0).
IfocGains design_ifoc(const MotorParameters& motor, const IfocSpec& spec);

}  // namespace imd::control
