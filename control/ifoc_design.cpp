#include "control/ifoc_design.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace imd::control {

IfocGains design_ifoc(const MotorParameters& motor, const IfocSpec& spec) {
  const VoltageFedConstants k = derive_voltage_fed(motor);
  const Real T = spec.sample_period_s;
  IfocGains g;
  g.sample_period_s = T;
  g.current_bandwidth_rad_s = spec.current_bandwidth_rad_s > 0 ? spec.current_bandwidth_rad_s
                                                               : default_current_bandwidth_rad_s(T);
  g.speed_bandwidth_rad_s =
      spec.speed_bandwidth_rad_s > 0
          ? spec.speed_bandwidth_rad_s
          : default_speed_bandwidth_rad_s(g.current_bandwidth_rad_s,
                                          spec.speed_feedback_bandwidth_rad_s);

  // One axis after the feed-forward: i(k+1) = a i(k) + b u(k).
  const Real a = std::exp(-k.gamma_per_s * T);
  const Real b = -std::expm1(-k.gamma_per_s * T) / (k.sigma_H * k.gamma_per_s);
  g.current_pole = std::exp(-g.current_bandwidth_rad_s * T);
  g.current_kp_V_per_A = (1 - g.current_pole) / b;
  g.current_ki_V_per_A = g.current_kp_V_per_A * (1 - a);
  g.speed = design_speed_pi(motor.J_kgm2, g.speed_bandwidth_rad_s, spec.torque_limit_Nm, T);

  g.sigma_H = k.sigma_H;
  g.gamma_per_s = k.gamma_per_s;
  g.alpha_per_s = k.alpha_per_s;
  g.rotor_flux_decay = std::exp(-k.alpha_per_s * T);
  g.Lm_H = motor.Lm_H;
  g.Ls_H = motor.Ls_H;
  g.Rs_Ohm = motor.Rs_Ohm;
  g.Lm_over_Lr = motor.Lm_H / motor.Lr_H;
  g.torque_constant_Nm_per_Wb_A = kClarkeTorqueFactor * Real(motor.pole_pairs) * g.Lm_over_Lr;
  g.pole_pairs = motor.pole_pairs;
  g.J_kgm2 = motor.J_kgm2;
  g.friction_Nms = motor.friction_Nms;
  g.torque_limit_Nm = spec.torque_limit_Nm;
  g.current_limit_A = spec.current_limit_A;
  g.field_weakening_voltage_share = spec.field_weakening_voltage_share;
  g.min_flux_Wb = spec.min_flux_Wb;
  g.latency_ticks = spec.latency_ticks;
  return g;
}

}  // namespace imd::control
