#pragma once
/// Speed reference as a function of time: a sine about an offset, or steps. Part of the core
/// (no heap): the MCU of a processor-in-the-loop run computes the scenario's reference itself.
#include <array>
#include <cstddef>

namespace imd::sim {

struct SpeedProfile {
  static constexpr std::size_t kMaxSteps = 32;  ///< the scenario loader rejects more
  enum class Kind { sine, steps };
  Kind kind = Kind::sine;
  double amplitude_rad_s = 0.0, frequency_Hz = 0.0, offset_rad_s = 0.0;  ///< sine
  /// steps: values_rad_s[i] from times_s[i] on (times increasing), 0 before the first.
  std::array<double, kMaxSteps> times_s{}, values_rad_s{};
  std::size_t step_count = 0;  ///< steps used, <= kMaxSteps

  /// The reference at t_s [rad/s]; tick context.
  double at(double t_s) const noexcept;
};

}  // namespace imd::sim
