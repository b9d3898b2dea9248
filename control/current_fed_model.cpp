#include "control/current_fed_model.hpp"

#include <cmath>

namespace imd::control {

double phi1(double x) noexcept {
  return x == 0.0 ? 1.0 : std::expm1(x) / x;
}

CurrentFedCoefficients discretize_current_fed(const MotorParameters& motor, double T0_s) {
  const CurrentFedConstants k = derive_current_fed(motor);
  const double friction_per_s = motor.friction_Nms / motor.J_kgm2;  // c / J
  CurrentFedCoefficients c;
  c.T0_s = T0_s;
  c.eta_per_s = k.eta_per_s;
  c.flux_decay = std::exp(-k.eta_per_s * T0_s);
  c.flux_from_i_now_H = motor.Ls_H * (1.0 - k.sigma - c.flux_decay);
  c.flux_from_i_next_H = motor.Ls_H * k.sigma;
  c.torque_per_flux_A = kClarkeTorqueFactor * motor.pole_pairs;
  c.speed_decay = std::exp(-friction_per_s * T0_s);
  c.speed_decay_minus_one = std::expm1(-friction_per_s * T0_s);
  // (e^{-aT} - e^{-bT}) / (J (b - a)) = e^{-aT} T phi1(-(b - a) T) / J with a = c/J, b = eta:
  // no cancellation when J eta is close to c.
  c.torque_to_speed =
      c.speed_decay * T0_s * phi1(-(k.eta_per_s - friction_per_s) * T0_s) / motor.J_kgm2;
  // (1 - e^{-aT}) / c = T phi1(-aT) / J, which is T0/J at c = 0.
  c.load_to_speed = -T0_s * phi1(-friction_per_s * T0_s) / motor.J_kgm2;
  return c;
}

}  // namespace imd::control
