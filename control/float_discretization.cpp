// The exact discretizations of both papers computed in float, for the MCU, where the drive
// recomputes them outside the tick for a tracked rotor resistance. The double reference is
// discretize_voltage_fed and discretize_current_fed; the error bounds are in their headers and
// in docs/derivations.md ("The discretization in float").
#include <Eigen/Core>
#include <cmath>

#include "control/current_fed_model.hpp"
#include "control/metzler_exponential.hpp"
#include "control/voltage_fed_model.hpp"

namespace imd::control {

VoltageFedFloatGenerators voltage_fed_float_generators(const MotorParameters& motor,
                                                       Real delta_s) noexcept {
  const float rs = float(motor.Rs_Ohm), ls = float(motor.Ls_H), lm = float(motor.Lm_H);
  const float rr = float(motor.Rr_Ohm), lr = float(motor.Lr_H), j = float(motor.J_kgm2);
  const float delta = float(delta_s);
  const float sigma_lr = leakage_product_H2(ls, lr, lm);  // sigma_H Lr = Ls Lr - Lm^2 (motor_parameters.hpp)
  const float alpha = rr / lr;
  const float beta = lm / sigma_lr;
  const float inv_sigma = lr / sigma_lr;
  // gamma = alpha beta Lm + Rs / sigma: two positive terms.
  const float gamma = alpha * beta * lm + rs * inv_sigma;
  VoltageFedFloatGenerators g;
  g.axis << -alpha * delta, alpha * lm * delta, 0.0f,  //
      alpha * beta * delta, -gamma * delta, inv_sigma * delta, 0.0f, 0.0f, 0.0f;
  // The additive compound (voltage_fed_model.cpp), written out: Metzler as well.
  g.compound << -(alpha + gamma) * delta, inv_sigma * delta, 0.0f,  //
      0.0f, -alpha * delta, alpha * lm * delta,                     //
      0.0f, alpha * beta * delta, -gamma * delta;
  g.friction = -float(motor.friction_Nms) / j * delta;
  g.mu_1_per_kgm2 = float(kClarkeTorqueFactor) * lm * float(motor.pole_pairs) / (j * lr);
  g.inv_J_1_per_kgm2 = 1.0f / j;
  g.delta_s = delta;
  return g;
}

template <>
VoltageFedCoefficients discretize_voltage_fed<float>(const MotorParameters& motor, Real delta_s) {
  const VoltageFedFloatGenerators g = voltage_fed_float_generators(motor, delta_s);
  const float delta = g.delta_s;
  VoltageFedCoefficients c;
  c.delta_s = delta_s;

  // A_d and B_d: blocks of exp(A3 delta). The Van Loan blocks of the compound give the
  // skew product's weighted integrals (voltage_fed_model.cpp), in the time u / delta.
  const Eigen::Matrix3f e3 = metzler_block_exponential<float, 3>(g.axis, 0.0f).e_x;
  c.a11 = e3(0, 0);
  c.a12 = e3(0, 1);
  c.a21 = e3(1, 0);
  c.a22 = e3(1, 1);
  c.b1 = e3(0, 2);
  c.b2 = e3(1, 2);
  const MetzlerExponential<float, 3> van_loan =
      metzler_block_exponential<float, 3>(g.compound, g.friction);
  const float y_scale = g.mu_1_per_kgm2 * delta;
  const float z_scale = y_scale * delta;
  c.eta1 = y_scale * van_loan.y(0, 0);
  c.eta2 = -y_scale * van_loan.y(0, 1);
  c.eta3 = -y_scale * van_loan.y(0, 2);
  c.kappa1 = z_scale * van_loan.z(0, 0);
  c.kappa2 = -z_scale * van_loan.z(0, 1);
  c.kappa3 = -z_scale * van_loan.z(0, 2);

  // Mechanical part: with X = 0 and g = -f delta, Y = phi1(g) and Z = phi2(g) (1x1 blocks).
  const MetzlerExponential<float, 1> mech =
      metzler_block_exponential<float, 1>(Eigen::Matrix<float, 1, 1>::Zero(), g.friction);
  c.omega_decay = mech.e_g;
  c.omega_decay_minus_one = std::expm1(g.friction);
  c.omega_to_theta_s = delta * mech.y(0, 0);
  c.load_to_omega = -(delta * g.inv_J_1_per_kgm2) * mech.y(0, 0);
  c.load_to_theta = -(delta * delta * g.inv_J_1_per_kgm2) * mech.z(0, 0);
  return c;
}

float phi1(float x) noexcept {
  return x == 0.0f ? 1.0f : std::expm1(x) / x;
}

template <>
CurrentFedCoefficients discretize_current_fed<float>(const MotorParameters& motor, Real T0_s) {
  const float ls = float(motor.Ls_H), lm = float(motor.Lm_H), lr = float(motor.Lr_H);
  const float j = float(motor.J_kgm2), t0 = float(T0_s);
  const float eta = float(motor.Rr_Ohm) / lr;
  const float friction_per_s = float(motor.friction_Nms) / j;  // c / J
  const float sigma = leakage_product_H2(ls, lr, lm) / (lr * ls);
  CurrentFedCoefficients c;
  c.T0_s = T0_s;
  c.eta_per_s = eta;
  c.flux_decay = std::exp(-eta * t0);
  // 1 - sigma - e^{-eta T0} = -(sigma + expm1(-eta T0)): sigma from the fused difference.
  c.flux_from_i_now_H = -ls * (sigma + std::expm1(-eta * t0));
  c.flux_from_i_next_H = ls * sigma;
  c.torque_per_flux_A = float(kClarkeTorqueFactor) * float(motor.pole_pairs);
  const float speed_decay = std::exp(-friction_per_s * t0);
  c.speed_decay = speed_decay;
  c.speed_decay_minus_one = std::expm1(-friction_per_s * t0);
  c.torque_to_speed = speed_decay * t0 * phi1(-(eta - friction_per_s) * t0) / j;
  c.load_to_speed = -t0 * phi1(-friction_per_s * t0) / j;
  return c;
}

}  // namespace imd::control
