#pragma once
/// Load torque as a function of time: constant, a square wave, or steps. No heap: part of the
/// core that also builds for the MCU.
#include <array>
#include <cstddef>

namespace imd::sim {

struct LoadProfile {
  static constexpr std::size_t kMaxSteps = 32;  ///< the scenario loader rejects more
  enum class Kind { constant, square, steps };
  Kind kind = Kind::constant;
  double value_Nm = 0.0;                               ///< constant
  double low_Nm = 0.0, high_Nm = 0.0, period_s = 1.0;  ///< square: low for the first half period
  /// steps: values_Nm[i] from times_s[i] on (times increasing), 0 before the first.
  std::array<double, kMaxSteps> times_s{}, values_Nm{};
  std::size_t step_count = 0;  ///< steps used, <= kMaxSteps

  /// The load at t_s [N m]; tick context.
  double at(double t_s) const noexcept;
};

}  // namespace imd::sim
