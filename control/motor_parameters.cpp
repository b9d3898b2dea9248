#include "control/motor_parameters.hpp"

#include <cmath>

namespace imd::control {

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
  // As a product of ratios, which neither overflows nor underflows where Lm^2 or Ls Lr would.
  if ((m.Lm_H / m.Ls_H) * (m.Lm_H / m.Lr_H) > 1 - kMinLeakageFactor) {
    return ParameterProblem{"Lm_H", m.Lm_H, "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"};
  }
  return std::nullopt;
}

}  // namespace imd::control
