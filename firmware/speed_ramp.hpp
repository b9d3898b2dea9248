#pragma once
/// Acceleration limit on the speed reference the control law sees. The ramp starts from the
/// measured speed when the drive starts running, so that a reference which moved on while the
/// motor was magnetizing is approached at a bounded rate rather than in one period. Tick context.
#include <algorithm>
#include <cmath>

#include "control/real.hpp"

namespace imd::firmware {

template <typename T>
class SpeedRamp {
 public:
  /// max_accel_rad_s2 may be infinite (no limit).
  SpeedRamp(Real max_accel_rad_s2, Real period_s) noexcept
      : max_step_(step(max_accel_rad_s2, period_s)) {}

  /// Changes the limit, as the largest change per period (the stop ramp uses its own); an
  /// infinite step means no limit. Tick context: computed beforehand with step(), not here.
  void set_max_step(T max_step_rad_s) noexcept { max_step_ = max_step_rad_s; }
  /// The per-period step of an acceleration limit (construction only).
  static T step(Real max_accel_rad_s2, Real period_s) noexcept {
    return T(max_accel_rad_s2 * period_s);
  }
  T value() const noexcept { return value_; }
  bool limited() const noexcept { return std::isfinite(max_step_); }
  void reset(T omega_rad_s) noexcept { value_ = omega_rad_s; }
  /// The ramp's value one period after `from`, heading for `target`.
  T next(T from, T target) const noexcept {
    if (!std::isfinite(max_step_)) return target;
    return from + std::clamp(target - from, -max_step_, max_step_);
  }
  void advance(T target) noexcept { value_ = next(value_, target); }

 private:
  T max_step_;
  T value_ = T(0);
};

}  // namespace imd::firmware
