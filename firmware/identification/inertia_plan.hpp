#pragma once
/// The rotating step's plan from the nameplate and the board (docs/identification.md, "Inertia
/// and friction"). Construction only (in the design arithmetic Real), in the service loop.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "control/real.hpp"
#include "firmware/identification/inertia_identifier.hpp"
#include "firmware/identification/nameplate.hpp"

namespace imd::firmware {

/// Rotor inertia of a catalogue motor of this nameplate, kg m^2: J = 0.0025 P^1.25 (P in kW)
/// fits 4-pole IEC motors from 0.75 kW (0.0018) to 37 kW (0.23), scaled with pole pairs / 2.
/// The rated power is taken as sqrt(3) V I x 0.85 (power factor) x 0.85 (efficiency). It only
/// sizes the test's torque, and stands in for J when the rotor may not turn.
inline Real catalogue_inertia_kgm2(const Nameplate& n) {
  const Real p_kW =
      std::sqrt(Real(3.0)) * n.rated_voltage_V * n.rated_current_A * Real(0.85) * Real(0.85) / 1000;
  // P^1.25 = P * P^(1/4): two square roots, not pow (2.9 KB of soft-double code on the MCU).
  return Real(0.0025) * p_kW * std::sqrt(std::sqrt(p_kW)) * Real(n.pole_pairs) / 2;
}

/// The limits of the test: 0.9 of the smaller of the rated peak current and the board's limit,
/// the linear SVPWM range of the bus; the rest of the sizing needs the identified motor and is
/// done by InertiaIdentifier's constructor.
inline InertiaPlan plan_inertia_test(const Nameplate& n, Real i_max_A, Real v_bus_V, Real period_s,
                                     Real counts_per_rev) {
  InertiaPlan p;
  p.period_s = period_s;
  p.rad_per_count = 2 * std::numbers::pi_v<Real> / counts_per_rev;
  p.omega_rated_rad_s = 2 * std::numbers::pi_v<Real> * n.rated_frequency_Hz;
  p.v_phase_peak_V = std::sqrt(Real(2.0) / Real(3.0)) * n.rated_voltage_V;
  p.i_limit_A = Real(0.9) * std::min(std::sqrt(Real(2.0)) * n.rated_current_A, i_max_A);
  p.v_limit_V = Real(0.95) * v_bus_V / std::sqrt(Real(3.0));
  p.J_guess_kgm2 = catalogue_inertia_kgm2(n);
  p.pole_pairs = n.pole_pairs;
  return p;
}

}  // namespace imd::firmware
