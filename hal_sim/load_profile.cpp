#include "hal_sim/load_profile.hpp"

#include <cmath>

namespace imd::sim {

double LoadProfile::at(double t_s) const noexcept {
  switch (kind) {
    case Kind::constant:
      return value_Nm;
    case Kind::square: {
      const double phase = t_s / period_s - std::floor(t_s / period_s);
      return phase < 0.5 ? low_Nm : high_Nm;
    }
    case Kind::steps: {
      double value = 0.0;
      for (std::size_t i = 0; i < step_count && times_s[i] <= t_s; ++i) value = values_Nm[i];
      return value;
    }
  }
  return 0.0;
}

}  // namespace imd::sim
