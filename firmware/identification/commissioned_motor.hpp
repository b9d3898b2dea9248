#pragma once
/// The motor record a commissioning gives (docs/identification.md, "What can be identified"):
/// Rs, Ls and tau_r as measured, Lr = Ls by the convention of equal leakages,
/// Lm = sqrt(Ls Lm^2/Lr), Rr = Lr / tau_r; J and the viscous friction as the rotating step
/// measured them. Without that step (the shaft may not turn, or did not), the mechanics of the
/// record before are kept; without one, the inertia is the catalogue rule's and the friction
/// zero. A friction measured below zero (noise around a frictionless shaft) is stored as zero.
/// Outside the tick.
#include <algorithm>
#include <optional>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "firmware/identification/inertia_identifier.hpp"
#include "firmware/identification/inertia_plan.hpp"
#include "firmware/identification/standstill_identifier.hpp"

namespace imd::firmware {

template <typename T>
control::MotorParameters commissioned_motor(const StandstillResult<T>& r, const Nameplate& n,
                                            const std::optional<control::MotorParameters>& before,
                                            const std::optional<Mechanics<T>>& mechanics = {}) {
  control::MotorParameters m;
  m.Rs_Ohm = Real(r.Rs_Ohm);
  m.Ls_H = Real(r.Ls_H);
  m.Lr_H = m.Ls_H;
  m.Lm_H = std::sqrt(m.Ls_H * Real(r.Lm2_over_Lr_H));
  m.Rr_Ohm = m.Lr_H / Real(r.tau_r_s);
  m.pole_pairs = n.pole_pairs;
  if (mechanics) {
    m.J_kgm2 = Real(mechanics->J_kgm2);
    m.friction_Nms = std::max(Real(0), Real(mechanics->friction_Nms));
  } else {
    m.J_kgm2 = before ? before->J_kgm2 : catalogue_inertia_kgm2(n);
    m.friction_Nms = before ? before->friction_Nms : 0;
  }
  return m;
}

}  // namespace imd::firmware
