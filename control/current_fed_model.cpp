#include "control/current_fed_model.hpp"

#include <cmath>

namespace imd::control {

double phi1(double x) noexcept {
  return x == 0.0 ? 1.0 : std::expm1(x) / x;
}

// In double whatever Real is, rounded to Real once (as the voltage-fed reference).
CurrentFedCoefficients discretize_current_fed(const MotorParameters& motor, Real period_s) {
  const CurrentFedConstantsIn<double> k = derive_current_fed<double>(motor);
  const double eta_per_s = k.eta_per_s, sigma = k.sigma, Ls_H = motor.Ls_H, J_kgm2 = motor.J_kgm2;
  const double friction_per_s = double(motor.friction_Nms) / J_kgm2;  // c / J
  const double T0_s = period_s;
  const double flux_decay = std::exp(-eta_per_s * T0_s);
  const double speed_decay = std::exp(-friction_per_s * T0_s);
  CurrentFedCoefficients c;
  c.T0_s = period_s;
  c.eta_per_s = Real(k.eta_per_s);
  c.flux_decay = Real(flux_decay);
  c.flux_from_i_now_H = Real(Ls_H * (1.0 - sigma - flux_decay));
  c.flux_from_i_next_H = Real(Ls_H * sigma);
  c.torque_per_flux_A = kClarkeTorqueFactor * Real(motor.pole_pairs);
  c.speed_decay = Real(speed_decay);
  c.speed_decay_minus_one = Real(std::expm1(-friction_per_s * T0_s));
  // (e^{-aT} - e^{-bT}) / (J (b - a)) = e^{-aT} T phi1(-(b - a) T) / J with a = c/J, b = eta:
  // no cancellation when J eta is close to c.
  c.torque_to_speed =
      Real(speed_decay * T0_s * phi1(-(eta_per_s - friction_per_s) * T0_s) / J_kgm2);
  // (1 - e^{-aT}) / c = T phi1(-aT) / J, which is T0/J at c = 0.
  c.load_to_speed = Real(-T0_s * phi1(-friction_per_s * T0_s) / J_kgm2);
  return c;
}

}  // namespace imd::control
