#include "control/motor_parameters.hpp"

#include <cmath>

namespace imd::control {

VoltageFedConstants derive_voltage_fed(const MotorParameters& m) noexcept {
  VoltageFedConstants c;
  c.sigma_H = m.Ls_H - m.Lm_H * m.Lm_H / m.Lr_H;
  c.alpha_per_s = m.Rr_Ohm / m.Lr_H;
  c.beta_per_H = m.Lm_H / (c.sigma_H * m.Lr_H);
  c.gamma_per_s = m.Lm_H * m.Lm_H * m.Rr_Ohm / (c.sigma_H * m.Lr_H * m.Lr_H) + m.Rs_Ohm / c.sigma_H;
  c.mu_per_kgm2 = kClarkeTorqueFactor * m.Lm_H * Real(m.pole_pairs) / (m.J_kgm2 * m.Lr_H);
  return c;
}

CurrentFedConstants derive_current_fed(const MotorParameters& m) noexcept {
  CurrentFedConstants c;
  c.sigma = 1 - m.Lm_H * m.Lm_H / (m.Lr_H * m.Ls_H);
  c.eta_per_s = m.Rr_Ohm / m.Lr_H;
  c.zeta_per_H_s = m.Rr_Ohm / (c.sigma * m.Lr_H * m.Ls_H);
  c.gamma_per_s = (m.Lr_H * m.Rs_Ohm + m.Ls_H * m.Rr_Ohm) / (c.sigma * m.Lr_H * m.Ls_H);
  return c;
}

std::optional<ParameterProblem> find_invalid_parameter(const MotorParameters& m) noexcept {
  struct Positive {
    std::string_view key;
    Real value;
  };
  const Positive positives[] = {{"Rs_Ohm", m.Rs_Ohm},
                                {"Ls_H", m.Ls_H},
                                {"Lm_H", m.Lm_H},
                                {"Rr_Ohm", m.Rr_Ohm},
                                {"Lr_H", m.Lr_H},
                                {"J_kgm2", m.J_kgm2},
                                {"pole_pairs", static_cast<Real>(m.pole_pairs)}};
  for (const auto& p : positives) {
    if (!std::isfinite(p.value)) return ParameterProblem{p.key, p.value, "must be finite"};
    if (p.value <= 0) return ParameterProblem{p.key, p.value, "must be > 0"};
  }
  if (!std::isfinite(m.friction_Nms)) {
    return ParameterProblem{"friction_Nms", m.friction_Nms, "must be finite"};
  }
  if (m.friction_Nms < 0) return ParameterProblem{"friction_Nms", m.friction_Nms, "must be >= 0"};
  // Lm^2 >= Ls Lr means no leakage inductance (sigma <= 0): the stator current equation of
  // model (1) would divide by zero or run backwards. The bound keeps the leakage factor at
  // kMinLeakageFactor or more, orders of magnitude above the rounding of either arithmetic
  // (a coupling that is "just" leaky by one rounding would divide the designs by it).
  if (m.Lm_H * m.Lm_H > (1 - kMinLeakageFactor) * m.Ls_H * m.Lr_H) {
    return ParameterProblem{"Lm_H", m.Lm_H, "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"};
  }
  return std::nullopt;
}

}  // namespace imd::control
