#pragma once
/// Discrete PI speed controller producing a torque reference, with a torque limit and
/// anti-windup by conditional integration: the integrator does not grow while the output is
/// saturated in the direction the error pushes, nor when a later stage reports that the torque
/// was trimmed (undo_last_integration). Tick context except the constructor.
#include <algorithm>

#include "control/real.hpp"

namespace imd::control {

struct SpeedPiConfig {
  Real kp_Nm_per_rad_s = 0.0;  ///< proportional gain
  Real ki_Nm_per_rad = 0.0;    ///< integral gain (per second of integrated error)
  Real torque_limit_Nm = 0.0;  ///< |output| <= this
  Real period_s = Real(1e-3);
};

/// Gains for a speed loop of bandwidth w_c on inertia J (Kp = J w_c, integral time 4 / w_c,
/// which keeps the integral zero a decade-ish below the crossover).
inline SpeedPiConfig design_speed_pi(Real J_kgm2, Real bandwidth_rad_s, Real torque_limit_Nm,
                                     Real period_s) {
  const Real kp = J_kgm2 * bandwidth_rad_s;
  return {kp, kp * bandwidth_rad_s / 4, torque_limit_Nm, period_s};
}

template <typename T>
class SpeedPi {
 public:
  explicit SpeedPi(const SpeedPiConfig& c) noexcept
      : kp_(T(c.kp_Nm_per_rad_s)),
        ki_T0_(T(c.ki_Nm_per_rad * c.period_s)),
        limit_(T(c.torque_limit_Nm)) {}

  /// Torque reference from the speed error and a torque feed-forward (the torque the
  /// reference's acceleration and the friction take). Returns a value within +-limit.
  T step(T omega_ref_rad_s, T omega_rad_s, T feedforward_Nm = T(0)) noexcept {
    const T error = omega_ref_rad_s - omega_rad_s;
    const T unclamped = kp_ * error + integral_ + feedforward_Nm;
    const T output = std::clamp(unclamped, -limit_, limit_);
    const bool pushing_further =
        (unclamped > limit_ && error > T(0)) || (unclamped < -limit_ && error < T(0));
    const T before = integral_;
    if (!pushing_further) integral_ = std::clamp(integral_ + ki_T0_ * error, -limit_, limit_);
    last_increment_ = integral_ - before;
    saturated_ = output != unclamped;
    return output;
  }
  bool saturated() const noexcept { return saturated_; }
  /// The torque asked for was not delivered (trimmed downstream): take back this step's
  /// integration so that the integrator does not wind up against that limit either.
  void undo_last_integration() noexcept {
    integral_ -= last_increment_;
    last_increment_ = T(0);
  }
  void reset(T integral_Nm = T(0)) noexcept { integral_ = integral_Nm; }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const SpeedPi& old) noexcept {
    integral_ = old.integral_;
    last_increment_ = old.last_increment_;
    saturated_ = old.saturated_;
  }

 private:
  T kp_, ki_T0_, limit_;
  T integral_ = T(0);
  T last_increment_ = T(0);
  bool saturated_ = false;
};

}  // namespace imd::control
