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
#include "control/real.hpp"
#include "firmware/drive_config.hpp"

namespace imd::firmware {

template <typename T>
class DcBrake {
 public:
  DcBrake(const control::MotorParameters& m, const DriveConfig& c) noexcept
      : current_A_(T(c.protection.dc_brake_current_share * c.current_margin * c.i_max_A)) {
    const Real bandwidth_rad_s = control::default_current_bandwidth_rad_s(c.sample_period_s);
    const Real sigma_H = control::derive_voltage_fed(m).sigma_H;
    kp_V_per_A_ = T(sigma_H * bandwidth_rad_s);
    ki_V_per_A_tick_ = T(m.Rs_Ohm * bandwidth_rad_s * c.sample_period_s);
    const Real tau_r_s = m.Lr_H / m.Rr_Ohm;
    const Real current_A = Real(current_A_);
    // No current (no current limit given): no DC braking.
    if (std::isfinite(current_A) && current_A > 0) {
      const Real k = control::kClarkeTorqueFactor * Real(m.pole_pairs) * m.Lm_H * m.Lm_H / m.Lr_H;
      ticks_per_unit_ = T(m.J_kgm2 / (k * current_A * current_A * Real(m.pole_pairs) * tau_r_s) /
                          c.sample_period_s);
    } else {
      current_A_ = T(0);
    }
    x_per_rad_s_ = T(Real(m.pole_pairs) * tau_r_s);
    x_stop_ = T(Real(m.pole_pairs) * tau_r_s * c.stop_speed_rad_s);
    settle_ticks_ = T(3 * tau_r_s / c.sample_period_s);
    const Real max_ticks = c.stop_timeout_s / c.sample_period_s;
    max_ticks_ = T(max_ticks < Real(1e7) ? max_ticks : Real(1e7));  // within float's integers
  }

  /// Starts braking from the speed at detection: the ticks it lasts, 0 if it cannot brake
  /// (no current, or no motion to stop). Resets the current loop.
  uint64_t begin(T omega_mech_rad_s) noexcept {
    integral_V_ = control::Vec2<T>::Zero();
    const T x0 = x_per_rad_s_ * std::abs(omega_mech_rad_s);
    if (current_A_ == T(0) || !(x0 > x_stop_)) return 0;
    const T ticks = std::min(
        ticks_per_unit_ * (std::log(x0 / x_stop_) + (x0 * x0 - x_stop_ * x_stop_) / T(2)) +
            settle_ticks_,
        max_ticks_);
    return uint64_t(static_cast<uint32_t>(ticks)) + 1;  // in T, and 32 bits: no double on the MCU
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
  T ticks_per_unit_ = T(0), x_per_rad_s_ = T(0), x_stop_ = T(0), settle_ticks_ = T(0);
  T max_ticks_ = T(0);
  control::Vec2<T> integral_V_ = control::Vec2<T>::Zero();
};

}  // namespace imd::firmware
