#pragma once
/// Induction-motor parameters and the derived constants of both papers.
///
/// Convention: the amplitude-invariant Clarke transform (alpha-beta quantities carry the phase
/// peak values). With it the electromagnetic torque is (3/2) p (Lm/Lr) I^T J Phi, as in paper
/// 000. Paper 001 writes its model with factor 1 (a power-invariant two-phase machine); the
/// project keeps one convention and carries 3/2 into paper 001's torque (docs/derivations.md,
/// Conventions).
#include <cmath>
#include <optional>
#include <string_view>
#include <type_traits>

#include "control/real.hpp"

namespace imd::control {

/// The most pole pairs a motor may have: the motor files, the drive's parameter record and the
/// nameplate share this bound, so that any motor file can be written to a drive.
inline constexpr int kMaxPolePairs = 32;

/// Torque factor of the amplitude-invariant Clarke transform: T = 3/2 p psi x i.
inline constexpr Real kClarkeTorqueFactor = 1.5;

/// Per-phase equivalent-circuit parameters of the motor and its rigid mechanical load.
struct MotorParameters {
  Real Rs_Ohm = 0.0;          ///< stator resistance
  Real Ls_H = 0.0;            ///< stator self inductance
  Real Lm_H = 0.0;            ///< mutual inductance (paper 001 writes m)
  Real Rr_Ohm = 0.0;          ///< rotor resistance, referred to the stator
  Real Lr_H = 0.0;            ///< rotor self inductance
  Real J_kgm2 = 0.0;          ///< moment of inertia of rotor and load
  int pole_pairs = 1;         ///< p (paper 000), n_p (paper 001)
  Real friction_Nms = 0.0;    ///< viscous friction c (paper 001); 0 in paper 000
};

/// Constants of model (1) of paper 000, in S (the design arithmetic by default; the double
/// references and the simulated plant take double whatever Real is).
template <typename S>
struct VoltageFedConstantsIn {
  S sigma_H = 0;      ///< sigma = Ls - Lm^2/Lr (stator transient inductance)
  S alpha_per_s = 0;  ///< alpha = Rr/Lr
  S beta_per_H = 0;   ///< beta = Lm/(sigma Lr)
  S gamma_per_s = 0;  ///< gamma = Lm^2 Rr/(sigma Lr^2) + Rs/sigma
  S mu_per_kgm2 = 0;  ///< mu = 3/2 Lm p/(J Lr)
};
using VoltageFedConstants = VoltageFedConstantsIn<Real>;

/// Constants of model (1) of paper 001 (stator flux and stator current as states).
template <typename S>
struct CurrentFedConstantsIn {
  S sigma = 0;         ///< leakage factor 1 - m^2/(lr ls), dimensionless
  S eta_per_s = 0;     ///< eta = rr/lr
  S zeta_per_H_s = 0;  ///< zeta = rr/(sigma lr ls)
  S gamma_per_s = 0;   ///< gamma = (lr rs + ls rr)/(sigma lr ls)
};
using CurrentFedConstants = CurrentFedConstantsIn<Real>;

/// sigma Lr Ls = Ls Lr - Lm^2, the leakage product, in float. Lm^2 is within a few percent of
/// Ls Lr, so the plain difference loses that factor's digits; Kahan's fused product difference
/// is within 2 ulp of the value the parameters give. (In double the plain difference's rounding,
/// 1e-16 times Ls / sigma, is far below any use: the derivations below keep it there.)
inline float leakage_product_H2(float Ls_H, float Lr_H, float Lm_H) noexcept {
  const float lm2 = Lm_H * Lm_H;
  const float lm2_error = std::fma(-Lm_H, Lm_H, lm2);  // lm2 - Lm^2, exactly
  return std::fma(Ls_H, Lr_H, -lm2) + lm2_error;
}

/// Paper 000 constants in S. Requires valid parameters (see find_invalid_parameter).
template <typename S = Real>
VoltageFedConstantsIn<S> derive_voltage_fed(const MotorParameters& m) noexcept {
  const S Ls = S(m.Ls_H), Lm = S(m.Lm_H), Lr = S(m.Lr_H), Rr = S(m.Rr_Ohm), Rs = S(m.Rs_Ohm);
  VoltageFedConstantsIn<S> c;
  if constexpr (std::is_same_v<S, float>) {
    c.sigma_H = leakage_product_H2(Ls, Lr, Lm) / Lr;
  } else {
    c.sigma_H = Ls - Lm * Lm / Lr;
  }
  c.alpha_per_s = Rr / Lr;
  c.beta_per_H = Lm / (c.sigma_H * Lr);
  c.gamma_per_s = Lm * Lm * Rr / (c.sigma_H * Lr * Lr) + Rs / c.sigma_H;
  c.mu_per_kgm2 = S(kClarkeTorqueFactor) * Lm * S(m.pole_pairs) / (S(m.J_kgm2) * Lr);
  return c;
}

/// Paper 001 constants in S. Requires valid parameters (see find_invalid_parameter).
template <typename S = Real>
CurrentFedConstantsIn<S> derive_current_fed(const MotorParameters& m) noexcept {
  const S Ls = S(m.Ls_H), Lm = S(m.Lm_H), Lr = S(m.Lr_H), Rr = S(m.Rr_Ohm), Rs = S(m.Rs_Ohm);
  CurrentFedConstantsIn<S> c;
  if constexpr (std::is_same_v<S, float>) {
    c.sigma = leakage_product_H2(Ls, Lr, Lm) / (Lr * Ls);
  } else {
    c.sigma = 1 - Lm * Lm / (Lr * Ls);
  }
  c.eta_per_s = Rr / Lr;
  c.zeta_per_H_s = Rr / (c.sigma * Lr * Ls);
  c.gamma_per_s = (Lr * Rs + Ls * Rr) / (c.sigma * Lr * Ls);
  return c;
}

/// The first parameter that makes a motor invalid, with the rule it breaks.
struct ParameterProblem {
  std::string_view key;   ///< key name as in the [motor] table, e.g. "Rs_Ohm"
  Real value;             ///< the offending value
  std::string_view rule;  ///< the requirement it breaks, e.g. "must be > 0"
};

/// The least leakage factor sigma = 1 - Lm^2 / (Ls Lr) a motor may have. Real machines have 0.02
/// to 0.15; 1e-3 refuses a coupling without leakage whatever the rounding of Lm (float's is
/// 6e-8), on which every design would divide by a rounding error.
inline constexpr Real kMinLeakageFactor = Real(1e-3);

/// Checks finiteness and signs, and that the magnetic coupling is physical:
/// Lm^2 <= (1 - kMinLeakageFactor) Ls Lr (otherwise the model has no leakage to speak of).
/// Returns nothing when valid.
std::optional<ParameterProblem> find_invalid_parameter(const MotorParameters& motor) noexcept;

}  // namespace imd::control
