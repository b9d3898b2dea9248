#pragma once
/// The two-level inverter's departures from its ideal average (docs/scenarios.md, [inverter]):
///
/// * **Dead time** t_d: both devices of a leg are off for t_d at each switching edge, and the
///   phase current's free-wheeling diode sets the pole voltage meanwhile. A positive current
///   (out of the leg) flows in the low diode, so the pole sits at 0 V when the high device
///   should already or still conduct: the pole voltage loses t_d/T v_bus on average over a PWM
///   period T, and a negative current gains it. A leg whose duty is 0 or 1 does not switch and
///   has no dead time.
/// * **Device drop** V_d: the conducting transistor or diode drops about V_d, again against the
///   current: the pole voltage loses sign(i) V_d.
///
/// Pole voltage = duty v_bus - sign(i) (t_d/T v_bus [switching legs] + V_d). The common mode of
/// the three errors does not reach an isolated star point; the alpha-beta error is their Clarke
/// transform. With a DC current I along phase a (i_b = i_c = -I/2) and every leg switching, the
/// alpha voltage loses 4/3 (t_d/T v_bus + V_d). The sign is the instantaneous current's: the
/// plant evaluates it at every integration stage, so a current through zero sees the switch
/// (no current ripple is modelled: the plant integrates the period's average voltage).
#include <array>

#include "control/svpwm.hpp"
#include "hal/pwm.hpp"

namespace imd::sim {

/// [inverter] dead_time_s, device_drop_V; zero: that part is ideal.
struct InverterNonideality {
  double dead_time_s = 0.0;    ///< per switching edge, >= 0 and < period/2
  double device_drop_V = 0.0;  ///< conducting device, >= 0

  bool ideal() const noexcept { return dead_time_s == 0.0 && device_drop_V == 0.0; }
};

/// The average voltage error (alpha-beta) over one PWM period `period_s` with these duties, bus
/// and stator current (alpha-beta). Zero for an ideal inverter.
inline control::Vec2<double> inverter_error_V(const InverterNonideality& inverter,
                                              const hal::PhaseDuties& duty, double v_bus_V,
                                              double period_s,
                                              const control::Vec2<double>& i_s_alphabeta_A) noexcept {
  const control::PhaseValues<double> i_abc = control::inverse_clarke(i_s_alphabeta_A);
  const double dead_time_V = inverter.dead_time_s / period_s * v_bus_V;
  control::PhaseValues<double> error{};
  for (int phase = 0; phase < 3; ++phase) {
    const double i = i_abc[phase];
    const double sign = i > 0.0 ? 1.0 : (i < 0.0 ? -1.0 : 0.0);
    const bool switching = duty[phase] > 0.0f && duty[phase] < 1.0f;
    error[phase] = -sign * ((switching ? dead_time_V : 0.0) + inverter.device_drop_V);
  }
  return control::clarke(error);
}

}  // namespace imd::sim
