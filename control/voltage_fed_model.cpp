#include "control/voltage_fed_model.hpp"

#include <Eigen/Core>
#include <cmath>

#include "control/block_exponential.hpp"

namespace imd::control {

Eigen::Matrix3d voltage_fed_axis_generator(const MotorParameters& motor) {
  const VoltageFedConstantsIn<double> k = derive_voltage_fed<double>(motor);
  const double alpha = k.alpha_per_s, beta = k.beta_per_H, gamma = k.gamma_per_s;
  const double sigma = k.sigma_H, Lm = motor.Lm_H;
  Eigen::Matrix3d a;
  a << -alpha, alpha * Lm, 0.0,           //
      alpha * beta, -gamma, 1.0 / sigma,  //
      0.0, 0.0, 0.0;
  return a;
}

Eigen::Matrix3d additive_compound(const Eigen::Matrix3d& a) {
  Eigen::Matrix3d m;
  m << a(0, 0) + a(1, 1), a(1, 2), -a(0, 2),  //
      a(2, 1), a(0, 0) + a(2, 2), a(0, 1),    //
      -a(2, 0), a(1, 0), a(1, 1) + a(2, 2);
  return m;
}

// The reference computes in double whatever Real is (the processor-in-the-loop image's metrics
// use it on the MCU too); its results are rounded to Real once, at the end.
VoltageFedCoefficients discretize_voltage_fed(const MotorParameters& motor, Real period_s) {
  const double mu_per_kgm2 = derive_voltage_fed<double>(motor).mu_per_kgm2;
  const double J_kgm2 = motor.J_kgm2;
  const double friction_per_s = double(motor.friction_Nms) / J_kgm2;
  const double delta_s = period_s;

  VoltageFedCoefficients c;
  c.delta_s = period_s;

  // Electrical part: A_d and B_d are blocks of exp(A3 delta).
  const Eigen::Matrix3d a3 = voltage_fed_axis_generator(motor);
  const Eigen::Matrix3d e3 = block_exponential<double>(a3 * delta_s, 0.0).e_x;
  c.a11 = Real(e3(0, 0));
  c.a12 = Real(e3(0, 1));
  c.a21 = Real(e3(1, 0));
  c.a22 = Real(e3(1, 1));
  c.b1 = Real(e3(0, 2));
  c.b2 = Real(e3(1, 2));

  // The skew product q(t) = I~^T J Phi~ is a combination of the 2x2 minors of rows (phi, i) of
  // exp(A3 t), i.e. of the first row of exp(M t) with M the additive compound. Speed and
  // position need its integrals weighted by the friction decay; both come out of one block
  // exponential (Van Loan):
  //   exp([M I 0; 0 -f I I; 0 0 0] delta) = [. Y Z; . . .; . . .],
  //   Y = int_0^delta exp(M u) exp(-f (delta - u)) du,
  //   Z = int_0^delta exp(M u) (1 - exp(-f (delta - u))) / f du  (-> (delta - u) as f -> 0).
  // Built in the dimensionless time u/delta, so that the three blocks are of one size:
  // exp([M delta, I, 0; 0, -f delta I, I; 0, 0, 0]) holds Y / delta and Z / delta^2.
  // block_exponential computes exactly this structured exponential without forming the 9x9.
  const BlockExponential<double> van_loan =
      block_exponential<double>(additive_compound(a3) * delta_s, -friction_per_s * delta_s);
  const Eigen::Matrix3d y = delta_s * van_loan.y;
  const Eigen::Matrix3d z = delta_s * delta_s * van_loan.z;
  // q = m00 I^T J Phi - m01 Phi^T J v - m02 I^T J v, with m the first row of exp(M t).
  c.eta1 = Real(mu_per_kgm2 * y(0, 0));
  c.eta2 = Real(-mu_per_kgm2 * y(0, 1));
  c.eta3 = Real(-mu_per_kgm2 * y(0, 2));
  c.kappa1 = Real(mu_per_kgm2 * z(0, 0));
  c.kappa2 = Real(-mu_per_kgm2 * z(0, 1));
  c.kappa3 = Real(-mu_per_kgm2 * z(0, 2));

  // Mechanical part: states (th, w, C_L) with dth = w, dw = -f w - C_L/J, dC_L = 0.
  Eigen::Matrix3d mech = Eigen::Matrix3d::Zero();
  mech(0, 1) = 1.0;
  mech(1, 1) = -friction_per_s;
  mech(1, 2) = -1.0 / J_kgm2;
  const Eigen::Matrix3d e_mech = block_exponential<double>(mech * delta_s, 0.0).e_x;
  c.omega_decay = Real(e_mech(1, 1));
  c.omega_decay_minus_one = Real(std::expm1(-friction_per_s * delta_s));
  c.omega_to_theta_s = Real(e_mech(0, 1));
  c.load_to_omega = Real(e_mech(1, 2));
  c.load_to_theta = Real(e_mech(0, 2));
  return c;
}

}  // namespace imd::control
