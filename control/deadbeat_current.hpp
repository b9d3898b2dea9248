#pragma once
/// Deadbeat stator-current control on the exact sampled model of paper 000: the rotor-frame
/// input v~ that brings I~ to a target in one period, I~_{k+1} = a21 Phi~ + a22 I~ + b2 v~,
/// clamped to the feasible inputs (the current then falls short of the target). It magnetizes
/// the motor, and it is the inner current loop that imposes paper 001's current commands on a
/// voltage inverter. Tick context.
#include "control/voltage_fed_model.hpp"
#include "control/frames.hpp"
#include "control/input_disk.hpp"

namespace imd::control {

template <typename T>
class DeadbeatCurrent {
 public:
  explicit DeadbeatCurrent(const VoltageFedCoefficients& c) noexcept
      : a21_(T(c.a21)), a22_(T(c.a22)), b2_(T(c.b2)) {}

  Vec2<T> input(const Vec2<T>& flux_r_AB_Wb, const Vec2<T>& i_s_AB_A, const Vec2<T>& i_target_AB_A,
                const InputDisk<T>& feasible) const noexcept {
    return feasible.clamp(wanted(flux_r_AB_Wb, i_s_AB_A, i_target_AB_A));
  }
  /// The input that reaches the target in one period, before the limits.
  Vec2<T> wanted(const Vec2<T>& flux_r_AB_Wb, const Vec2<T>& i_s_AB_A,
                 const Vec2<T>& i_target_AB_A) const noexcept {
    return (i_target_AB_A - a21_ * flux_r_AB_Wb - a22_ * i_s_AB_A) / b2_;
  }

 private:
  T a21_, a22_, b2_;
};

}  // namespace imd::control
