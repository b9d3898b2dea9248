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

namespace imd::control {

/// The most pole pairs a motor may have: the motor files, the drive's parameter record and the
/// nameplate share this bound, so that any motor file can be written to a drive.
inline constexpr int kMaxPolePairs = 32;

/// Torque factor of the amplitude-invariant Clarke transform: T = 3/2 p psi x i.
inline constexpr double kClarkeTorqueFactor = 1.5;

/// Per-phase equivalent-circuit parameters of the motor and its rigid mechanical load.
struct MotorParameters {
  double Rs_Ohm = 0.0;        ///< stator resistance
  double Ls_H = 0.0;          ///< stator self inductance
  double Lm_H = 0.0;          ///< mutual inductance (paper 001 writes m)
  double Rr_Ohm = 0.0;        ///< rotor resistance, referred to the stator
  double Lr_H = 0.0;          ///< rotor self inductance
  double J_kgm2 = 0.0;        ///< moment of inertia of rotor and load
  int pole_pairs = 1;         ///< p (paper 000), n_p (paper 001)
  double friction_Nms = 0.0;  ///< viscous friction c (paper 001); 0 in paper 000
};

/// Constants of model (1) of paper 000.
struct VoltageFedConstants {
  double sigma_H = 0.0;      ///< sigma = Ls - Lm^2/Lr (stator transient inductance)
  double alpha_per_s = 0.0;  ///< alpha = Rr/Lr
  double beta_per_H = 0.0;   ///< beta = Lm/(sigma Lr)
  double gamma_per_s = 0.0;  ///< gamma = Lm^2 Rr/(sigma Lr^2) + Rs/sigma
  double mu_per_kgm2 = 0.0;  ///< mu = 3/2 Lm p/(J Lr)
};

/// Constants of model (1) of paper 001 (stator flux and stator current as states).
struct CurrentFedConstants {
  double sigma = 0.0;         ///< leakage factor 1 - m^2/(lr ls), dimensionless
  double eta_per_s = 0.0;     ///< eta = rr/lr
  double zeta_per_H_s = 0.0;  ///< zeta = rr/(sigma lr ls)
  double gamma_per_s = 0.0;   ///< gamma = (lr rs + ls rr)/(sigma lr ls)
};

/// Paper 000 constants. Requires valid parameters (see find_invalid_parameter).
VoltageFedConstants derive_voltage_fed(const MotorParameters& motor) noexcept;

/// Paper 001 constants. Requires valid parameters (see find_invalid_parameter).
CurrentFedConstants derive_current_fed(const MotorParameters& motor) noexcept;

/// The first parameter that makes a motor invalid, with the rule it breaks.
struct ParameterProblem {
  std::string_view key;   ///< key name as in the [motor] table, e.g. "Rs_Ohm"
  double value;           ///< the offending value
  std::string_view rule;  ///< the requirement it breaks, e.g. "must be > 0"
};

/// Checks finiteness and signs, and that the magnetic coupling is physical: Lm^2 < Ls Lr
/// (otherwise sigma <= 0 and the model has no leakage). Returns nothing when valid.
std::optional<ParameterProblem> find_invalid_parameter(const MotorParameters& motor) noexcept;

}  // namespace imd::control
