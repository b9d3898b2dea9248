#pragma once
/// A scenario written for the rotor-flux laws (a rotor-flux reference, a speed profile) run
/// with any of the drive's laws, so that the tests and the soak can take every law through the
/// same motor, board and profile. The torque limit and the IOL's references and loops follow
/// from the motor and the board, as a user would set them.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <utility>

#include "control/ifoc_design.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::sim {

/// Mechanical base speed: where the no-load stator voltage at the flux reference,
/// i_d sqrt(Rs^2 + (w_e Ls)^2) with i_d = psi / Lm, reaches what SVPWM gives with the drive's
/// 0.95 modulation margin, 0.95 v_bus / sqrt(3).
inline double base_speed_rad_s(const Scenario& s, double flux2_Wb2) {
  const control::MotorParameters& m = s.motor;
  const double v_max = 0.95 * s.v_bus_V / std::sqrt(3.0);
  const double i_d = std::sqrt(flux2_Wb2) / m.Lm_H;
  return std::sqrt(std::pow(v_max / i_d, 2) - m.Rs_Ohm * m.Rs_Ohm) / m.Ls_H / m.pole_pairs;
}

/// A speed reference of steps {time, value}, 0 before the first.
inline SpeedProfile speed_steps(std::initializer_list<std::pair<double, double>> steps) {
  SpeedProfile p;
  p.kind = SpeedProfile::Kind::steps;
  for (const auto& [t_s, value] : steps) {
    p.times_s[p.step_count] = t_s;
    p.values_rad_s[p.step_count++] = value;
  }
  return p;
}

/// A load of steps {time, value}, 0 before the first.
inline LoadProfile load_steps(std::initializer_list<std::pair<double, double>> steps) {
  LoadProfile p;
  p.kind = LoadProfile::Kind::steps;
  for (const auto& [t_s, value] : steps) {
    p.times_s[p.step_count] = t_s;
    p.values_Nm[p.step_count++] = value;
  }
  return p;
}

/// The torque the current limit allows at a rotor flux (3/2 p Lm/Lr psi i_q, with |i| at the
/// drive's 0.95 current margin and i_d = psi / Lm): what the speed loops may ask for.
inline double torque_at_current_limit_Nm(const Scenario& s, double flux2_Wb2) {
  const control::MotorParameters& m = s.motor;
  const double flux = std::sqrt(flux2_Wb2), i_max = 0.95 * s.i_max_A;
  const double i_q = std::sqrt(std::max(i_max * i_max - std::pow(flux / m.Lm_H, 2), 0.0));
  return 1.5 * m.pole_pairs * m.Lm_H / m.Lr_H * flux * i_q;
}

/// `s` with `law` ("dsmc", "ifoc" or "iol"), its rotor-flux reference scaled by `flux_share`,
/// and the torque limit at that flux. The IOL gets the stator flux of the same rotor flux at no
/// load, (Ls/Lm)^2 psi_r^2, and its outer loops: the speed loop at the IFOC's speed bandwidth
/// (control/ifoc_design.hpp), the flux loop at 20 ms (above the 2 IOL periods it needs,
/// docs/iol.md).
inline Scenario with_law(Scenario s, const std::string& law, double flux_share = 1.0) {
  const control::MotorParameters& m = s.motor;
  // A file written for the IOL gives its stator flux: the rotor flux of the same at no load.
  if (s.controller == "iol") s.flux2_Wb2 = std::pow(m.Lm_H / m.Ls_H, 2) * s.stator_flux2_Wb2;
  s.flux2_Wb2 *= flux_share * flux_share;
  s.controller = law;
  s.torque_limit_Nm = torque_at_current_limit_Nm(s, s.flux2_Wb2);
  if (law == "iol") {
    s.stator_flux2_Wb2 = std::pow(m.Ls_H / m.Lm_H, 2) * s.flux2_Wb2;
    s.outer_speed_loop = s.outer_flux_loop = true;
    s.flux_loop_time_constant_s = 0.02;
    s.speed_loop_bandwidth_rad_s = control::default_speed_bandwidth_rad_s(
        control::default_current_bandwidth_rad_s(s.sample_period_s), s.encoder_bandwidth_rad_s);
  }
  return s;
}

}  // namespace imd::sim
