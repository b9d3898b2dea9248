#pragma once
/// DC-injection braking: a fault's stop when speed control is gone (the encoder failed at
/// speed). A direct current in the stator sets a field at rest; the turning rotor cuts it and
/// brakes like an induction motor at slip p w, with no position or speed feedback. The current
/// is held by a PI loop in the stator frame on the measured current (the IFOC's current-loop
/// rule: bandwidth f_s / 20, zero on the stator's R/sigma pole). Tick context except
/// construction.
///
/// How long it brakes (docs/safety.md, "Stop categories"): with I the current and
/// x = p tau_r w, the torque is K I^2 x / (1 + x^2), K = 3/2 p Lm^2/Lr, so the no-load time from
/// w0 down to the stop speed w_s is
///     t = J / (K I^2 p tau_r) [ln(x0 / x_s) + (x0^2 - x_s^2) / 2],
/// plus three rotor time constants for the flux to settle on the still field; at most the stop
/// timeout. A load that overhauls the braking torque is the holding brake's to stop.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "control/frames.hpp"
#include "control/ifoc_design.hpp"
#include "control/motor_parameters.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/duration_ticks.hpp"

namespace imd::firmware {

template <typename T>
class DcBrake {
 public:
  DcBrake(const control::MotorParameters& m, const DriveConfig& c) noexcept
      : current_A_(T(c.protection.dc_brake_current_share * c.current_margin * c.i_max_A)) {
    const double bandwidth_rad_s = control::default_current_bandwidth_rad_s(c.sample_period_s);
    const double sigma_H = control::derive_voltage_fed(m).sigma_H;
    kp_V_per_A_ = T(sigma_H * bandwidth_rad_s);
    ki_V_per_A_tick_ = T(m.Rs_Ohm * bandwidth_rad_s * c.sample_period_s);
    const double tau_r_s = m.Lr_H / m.Rr_Ohm;
    const double current_A = double(current_A_);
    // No current (no current limit given): no DC braking.
    if (std::isfinite(current_A) && current_A > 0.0) {
      const double k = 1.5 * m.pole_pairs * m.Lm_H * m.Lm_H / m.Lr_H;
      seconds_per_unit_ = m.J_kgm2 / (k * current_A * current_A * m.pole_pairs * tau_r_s);
    } else {
      current_A_ = T(0);
    }
    x_per_rad_s_ = m.pole_pairs * tau_r_s;
    x_stop_ = x_per_rad_s_ * c.stop_speed_rad_s;
    settle_s_ = 3.0 * tau_r_s;
    period_s_ = c.sample_period_s;
    max_s_ = c.stop_timeout_s;
  }

  /// Starts braking from the speed at detection: the ticks it lasts, 0 if it cannot brake
  /// (no current, or no motion to stop). Resets the current loop.
  uint64_t begin(T omega_mech_rad_s) noexcept {
    integral_V_ = control::Vec2<T>::Zero();
    const double x0 = x_per_rad_s_ * std::abs(double(omega_mech_rad_s));
    if (current_A_ == T(0) || !(x0 > x_stop_)) return 0;
    const double t_s = std::min(
        seconds_per_unit_ * (std::log(x0 / x_stop_) + (x0 * x0 - x_stop_ * x_stop_) / 2.0) +
            settle_s_,
        max_s_);
    return duration_ticks(t_s, period_s_);
  }

  /// The stator voltage that holds the current along alpha, within the disk v_max.
  control::Vec2<T> step(const control::Vec2<T>& i_alphabeta_A, T v_max_V) noexcept {
    const control::Vec2<T> error_A = control::Vec2<T>(current_A_, T(0)) - i_alphabeta_A;
    control::Vec2<T> u_V = kp_V_per_A_ * error_A + integral_V_;
    const T norm_V = u_V.norm();
    if (norm_V > v_max_V) {
      u_V *= v_max_V / norm_V;  // saturated: the integral holds (anti-windup)
    } else {
      integral_V_ += ki_V_per_A_tick_ * error_A;
    }
    return u_V;
  }

  T current_A() const noexcept { return current_A_; }

 private:
  T current_A_, kp_V_per_A_ = T(0), ki_V_per_A_tick_ = T(0);
  double seconds_per_unit_ = 0.0, x_per_rad_s_ = 0.0, x_stop_ = 0.0, settle_s_ = 0.0;
  double period_s_ = 0.0, max_s_ = 0.0;
  control::Vec2<T> integral_V_ = control::Vec2<T>::Zero();
};

}  // namespace imd::firmware
