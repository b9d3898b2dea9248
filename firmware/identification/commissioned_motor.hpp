#pragma once
/// The motor record a standstill commissioning gives (docs/identification.md, "What can be
/// identified"): Rs, Ls and tau_r as measured, Lr = Ls by the convention of equal leakages,
/// Lm = sqrt(Ls Lm^2/Lr), Rr = Lr / tau_r. The mechanics are not seen at standstill: the inertia
/// and friction of the record before are kept; without one, the inertia comes from the rated
/// power by a rule for catalogue motors, a placeholder for the inertia test. Outside the tick.
#include <cmath>
#include <optional>

#include "control/motor_parameters.hpp"
#include "firmware/identification/nameplate.hpp"
#include "firmware/identification/standstill_identifier.hpp"

namespace imd::firmware {

/// Rotor inertia of a catalogue motor of this nameplate, kg m^2: J = 0.0025 P^1.25 (P in kW)
/// fits 4-pole IEC motors from 0.75 kW (0.0018) to 37 kW (0.23), scaled with pole pairs / 2.
/// The rated power is taken as sqrt(3) V I x 0.85 (power factor) x 0.85 (efficiency).
inline double catalogue_inertia_kgm2(const Nameplate& n) {
  const double p_kW = std::sqrt(3.0) * n.rated_voltage_V * n.rated_current_A * 0.85 * 0.85 / 1e3;
  return 0.0025 * std::pow(p_kW, 1.25) * double(n.pole_pairs) / 2.0;
}

template <typename T>
control::MotorParameters commissioned_motor(const StandstillResult<T>& r, const Nameplate& n,
                                            const std::optional<control::MotorParameters>& before) {
  control::MotorParameters m;
  m.Rs_Ohm = double(r.Rs_Ohm);
  m.Ls_H = double(r.Ls_H);
  m.Lr_H = m.Ls_H;
  m.Lm_H = std::sqrt(m.Ls_H * double(r.Lm2_over_Lr_H));
  m.Rr_Ohm = m.Lr_H / double(r.tau_r_s);
  m.pole_pairs = n.pole_pairs;
  m.J_kgm2 = before ? before->J_kgm2 : catalogue_inertia_kgm2(n);
  m.friction_Nms = before ? before->friction_Nms : 0.0;
  return m;
}

}  // namespace imd::firmware
