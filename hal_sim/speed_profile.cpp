#include "hal_sim/speed_profile.hpp"

#include <cmath>
#include <numbers>

namespace imd::sim {

double SpeedProfile::at(double t_s) const noexcept {
  if (kind == Kind::sine) {
    return offset_rad_s + amplitude_rad_s * std::sin(2.0 * std::numbers::pi * frequency_Hz * t_s);
  }
  double value = 0.0;
  for (std::size_t i = 0; i < step_count && times_s[i] <= t_s; ++i) value = values_rad_s[i];
  return value;
}

}  // namespace imd::sim
