#pragma once
/// Induction-motor parameters and the derived constants of both papers.
///
/// Convention: the amplitude-invariant Clarke transform (alpha-beta quantities carry the phase
/// peak values). With it the electromagnetic torque is (3/2) p (Lm/Lr) I^T J Phi, as in paper
/// 000. Paper 001 writes its model with factor 1 (a power-invariant two-phase machine); the
/// project keeps one convention and carries 3/2 into paper 001's torque (docs/derivations.md,
/// Conventions).
#include <optional>
#include <string_view>

#include "control/real.hpp"

namespace imd::control {

/// The most pole pairs a motor may have: the motor files, the drive's parameter record and the
/// nameplate share this bound, so that any motor file can be written to a drive.
inline constexpr int kMaxPolePairs = 32;

/// Torque factor of the amplitude-invariant Clarke transform: T = 3/2 p psi x i.
inline constexpr Real kClarkeTorqueFactor = 1.5;

/// Per-phase equivalent-circuit parameters of the motor and its rigid mechanical load.
struct MotorParameters {
  Real Rs_Ohm = 0.0;        ///< stator resistance
  Real Ls_H = 0.0;          ///< stator self inductance
  Real Lm_H = 0.0;          ///< mutual inductance (paper 001 writes m)
  Real Rr_Ohm = 0.0;        ///< rotor resistance, referred to the stator
  Real Lr_H = 0.0;          ///< rotor self inductance
  Real J_kgm2 = 0.0;        ///< moment of inertia of rotor and load
  int pole_pairs = 1;         ///< p (paper 000), n_p (paper 001)
  Real friction_Nms = 0.0;  ///< viscous friction c (paper 001); 0 in paper 000
};

/// Constants of model (1) of paper 000.
struct VoltageFedConstants {
  Real sigma_H = 0.0;      ///< sigma = Ls - Lm^2/Lr (stator transient inductance)
  Real alpha_per_s = 0.0;  ///< alpha = Rr/Lr
  Real beta_per_H = 0.0;   ///< beta = Lm/(sigma Lr)
  Real gamma_per_s = 0.0;  ///< gamma = Lm^2 Rr/(sigma Lr^2) + Rs/sigma
  Real mu_per_kgm2 = 0.0;  ///< mu = 3/2 Lm p/(J Lr)
};

/// Constants of model (1) of paper 001 (stator flux and stator current as states).
struct CurrentFedConstants {
  Real sigma = 0.0;         ///< leakage factor 1 - m^2/(lr ls), dimensionless
  Real eta_per_s = 0.0;     ///< eta = rr/lr
  Real zeta_per_H_s = 0.0;  ///< zeta = rr/(sigma lr ls)
  Real gamma_per_s = 0.0;   ///< gamma = (lr rs + ls rr)/(sigma lr ls)
};

/// Paper 000 constants. Requires valid parameters (see find_invalid_parameter).
VoltageFedConstants derive_voltage_fed(const MotorParameters& motor) noexcept;

/// Paper 001 constants. Requires valid parameters (see find_invalid_parameter).
CurrentFedConstants derive_current_fed(const MotorParameters& motor) noexcept;

/// The first parameter that makes a motor invalid, with the rule it breaks.
struct ParameterProblem {
  std::string_view key;   ///< key name as in the [motor] table, e.g. "Rs_Ohm"
  Real value;           ///< the offending value
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
