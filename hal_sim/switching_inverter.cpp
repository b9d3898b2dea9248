#include "hal_sim/switching_inverter.hpp"

#include <algorithm>
#include <utility>

#include "control/svpwm.hpp"

namespace imd::sim {

control::Vec2<double> PwmPeriod::average_V() const noexcept {
  control::Vec2<double> sum = control::Vec2<double>::Zero();
  double total_s = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    sum += segments[i].duration_s * segments[i].u_alphabeta_V;
    total_s += segments[i].duration_s;
  }
  return total_s > 0.0 ? control::Vec2<double>(sum / total_s) : sum;
}

PwmPeriod switching_period(const InverterNonideality& inverter, const hal::PhaseDuties& duty,
                           double v_bus_V, double period_s,
                           const control::Vec2<double>& i_s_alphabeta_A) noexcept {
  const control::PhaseValues<double> i_abc = control::inverse_clarke(i_s_alphabeta_A);
  // Each leg's pole is high over [high_from, high_to] (empty when high_from >= high_to).
  std::array<double, 3> high_from{}, high_to{}, drop_V{};
  std::array<double, 8> edges{0.0, period_s};
  std::size_t edge_count = 2;
  for (int k = 0; k < 3; ++k) {
    const double d = std::clamp(double(duty[k]), 0.0, 1.0);
    const double sign = i_abc[k] > 0.0 ? 1.0 : (i_abc[k] < 0.0 ? -1.0 : 0.0);
    drop_V[k] = sign * inverter.device_drop_V;
    double from = 0.5 * (1.0 - d) * period_s, to = 0.5 * (1.0 + d) * period_s;
    if (d > 0.0 && d < 1.0) {  // a leg that switches has its dead time
      if (i_abc[k] >= 0.0) {
        from += inverter.dead_time_s;  // the low diode holds the pole until the high device is on
      } else {
        to += inverter.dead_time_s;  // the high diode holds it until the low device is on
      }
    }
    from = std::clamp(from, 0.0, period_s);
    to = std::clamp(to, 0.0, period_s);
    high_from[k] = from;
    high_to[k] = to;
    if (from < to) {
      edges[edge_count++] = from;
      edges[edge_count++] = to;
    }
  }
  for (std::size_t i = 1; i < edge_count; ++i) {  // insertion sort of at most 8 edges
    for (std::size_t j = i; j > 0 && edges[j] < edges[j - 1]; --j)
      std::swap(edges[j], edges[j - 1]);
  }
  PwmPeriod p;
  for (std::size_t e = 0; e + 1 < edge_count; ++e) {
    const double start = edges[e], end = edges[e + 1];
    if (end - start <= 1e-15 * period_s) continue;  // coincident edges
    const double middle = 0.5 * (start + end);
    control::PhaseValues<double> pole{};
    for (int k = 0; k < 3; ++k) {
      const bool high = middle > high_from[k] && middle < high_to[k];
      pole[k] = (high ? v_bus_V : 0.0) - drop_V[k];
    }
    p.segments[p.count++] = {end - start, control::clarke(pole)};
  }
  return p;
}

}  // namespace imd::sim
