#pragma once
/// The inverter at the level of its switches ([inverter] model = "switching"), to measure the
/// current ripple the average model (inverter_model.hpp) hides. One centre-aligned PWM period
/// per control period: leg k's high device is commanded on over [(1 - d_k) T/2, (1 + d_k) T/2],
/// the middle of the period, where the carrier is at its lowest; the ADC samples at the period's
/// ends, where the carrier peaks and the current passes its period average (synchronous
/// sampling).
///
/// Dead time t_d: each turn-on is delayed by t_d. In between, the phase current's diode sets the
/// pole: a positive current (out of the leg) holds it low, so the pole goes high t_d late and
/// low on time; a negative current holds it high, so it goes high on time and low t_d late. The
/// sign is taken at the period's start and held over it (a current through zero within the
/// period is switched one period late: an error of at most t_d v_bus over one period). Device
/// drop V_d: the conducting device or diode takes sign(i) V_d off the pole. The star point is
/// isolated: the Clarke transform of the pole voltages is the stator voltage.
///
/// The period splits at the legs' edges into at most 7 segments of constant voltage, which the
/// plant integrates one after the other (InductionMotorPlant::step_voltage_segments). Limits:
/// an edge delayed past the period's end (duty above 1 - 2 t_d / T with a negative current) is
/// cut at the end, not carried into the next period; at zero current the dead time is taken as
/// for a positive one.
#include <array>
#include <cstddef>

#include "control/frames.hpp"
#include "hal/pwm.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "hal_sim/inverter_model.hpp"

namespace imd::sim {

/// At most 6 edges split a period into 7 segments.
struct PwmPeriod {
  std::array<VoltageSegment, 7> segments{};
  std::size_t count = 0;
  /// The period's average stator voltage (what the average model would apply).
  control::Vec2<double> average_V() const noexcept;
};

/// The segments of one period of `period_s` with these duties, bus and stator current (alpha-
/// beta, at the period's start: the dead time's and the drop's sign).
PwmPeriod switching_period(const InverterNonideality& inverter, const hal::PhaseDuties& duty,
                           double v_bus_V, double period_s,
                           const control::Vec2<double>& i_s_alphabeta_A) noexcept;

}  // namespace imd::sim
