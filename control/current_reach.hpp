#pragma once
/// The stator currents a current loop can reach in a few sample periods under the voltage limit,
/// on the exact sampled model of paper 000 in the rotor frame:
///   I~_{k+1} = a21 Phi~ + a22 I~ + b2 v~,   v~ = u_AB - sigma p w J (I~ + beta Phi~),
/// with the stator voltage |u_AB| <= v_max (feedback (2): control/input_disk.hpp). In complex
/// notation (J = i) one period is I~_{k+1} = A I~ + F + b2 u_AB with A = a22 - i b2 sigma p w and
/// F = (a21 - i b2 sigma p w beta) Phi~: a scaling and a rotation. Over m periods, Phi~ held (it
/// moves with the rotor time constant), I~_m = A^m I~ + (1 + A + ... + A^{m-1}) F + sum_j
/// A^{m-1-j} b2 u_j, and as every u_j runs over its disk I~_m runs over the disk centred at the
/// free response (all u_j = 0) with radius b2 v_max (1 + |A| + ... + |A|^{m-1}).
///
/// Paper 001's law commands the current of the next period and assumes it there at the
/// period's boundary. A command that the loop cannot reach within the period does not arrive
/// before the law steps again, and a law that believes it did drifts from the motor
/// (docs/iol.md, "At the voltage limit"). Tick context.
#include <cmath>
#include <limits>

#include "control/frames.hpp"
#include "control/input_disk.hpp"
#include "control/motor_parameters.hpp"
#include "control/voltage_fed_model.hpp"

namespace imd::control {

template <typename T>
struct CurrentDisk {
  Vec2<T> center_A = Vec2<T>::Zero();
  T radius_A = std::numeric_limits<T>::infinity();  ///< +inf: every current (no voltage limit)

  bool unlimited() const noexcept { return radius_A == std::numeric_limits<T>::infinity(); }
  bool contains(const Vec2<T>& i_A) const noexcept {
    return unlimited() || (i_A - center_A).norm() <= radius_A;
  }
};

/// The largest disk inside both `reach` and the current limit |i| <= limit_A (+inf: none), the
/// reach kept where they do not meet: the geometry of control/input_disk.hpp, in amperes.
template <typename T>
CurrentDisk<T> within_current_limit(const CurrentDisk<T>& reach, T limit_A) noexcept {
  const InputDisk<T> both = inscribed_disk(InputDisk<T>{reach.center_A, reach.radius_A},
                                           InputDisk<T>{Vec2<T>::Zero(), limit_A});
  return {both.center_V, both.radius_V};
}

template <typename T>
class CurrentReach {
 public:
  /// `tick_model`: the voltage-fed model at the current loop's sample period.
  CurrentReach(const MotorParameters& motor, const VoltageFedCoefficients& tick_model) noexcept
      : a21_(T(tick_model.a21)),
        a22_(T(tick_model.a22)),
        b2_(T(tick_model.b2)),
        sigma_p_H_(T(derive_voltage_fed(motor).sigma_H * Real(motor.pole_pairs))),
        beta_per_H_(T(derive_voltage_fed(motor).beta_per_H)) {}

  /// The currents reachable `periods` sample periods after the state (flux_r, i_from) at
  /// mechanical speed omega with |u_AB| <= v_max_V. Unlimited for an infinite (or NaN) v_max_V.
  CurrentDisk<T> disk(const Vec2<T>& flux_r_AB_Wb, const Vec2<T>& i_from_AB_A, T omega_mech_rad_s,
                      T v_max_V, int periods) const noexcept {
    if (!(v_max_V < std::numeric_limits<T>::infinity())) return {};
    const T turn = b2_ * sigma_p_H_ * omega_mech_rad_s;  // A = a22 - i turn
    const Vec2<T> forced = a21_ * flux_r_AB_Wb - turn * beta_per_H_ * J_times<T>(flux_r_AB_Wb);
    const T gain = std::sqrt(a22_ * a22_ + turn * turn);  // |A|
    Vec2<T> center = i_from_AB_A;
    T radius = T(0), gain_power = T(1);
    for (int j = 0; j < periods; ++j) {  // a few periods, at the law's boundaries only
      center = a22_ * center - turn * J_times<T>(center) + forced;
      radius += gain_power;
      gain_power *= gain;
    }
    return {center, std::abs(b2_) * v_max_V * radius};
  }

 private:
  T a21_, a22_, b2_;
  T sigma_p_H_;  ///< sigma p: the feedback's gain on w J (I~ + beta Phi~)
  T beta_per_H_;
};

}  // namespace imd::control
