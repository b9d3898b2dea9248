#pragma once
/// Load torque as a function of time: constant, a square wave, or steps.
#include <vector>

namespace imd::sim {

struct LoadProfile {
  enum class Kind { constant, square, steps };
  Kind kind = Kind::constant;
  double value_Nm = 0.0;                               ///< constant
  double low_Nm = 0.0, high_Nm = 0.0, period_s = 1.0;  ///< square: low for the first half period
  std::vector<double> times_s, values_Nm;  ///< steps: values_Nm[i] from times_s[i] on; 0 before

  double at(double t_s) const noexcept;
};

}  // namespace imd::sim
