#pragma once
/// How the plant integrates a period: RK4 with `substeps` equal steps (the reference), or the
/// sixth-order method of rk6_integrator.hpp with as few steps as its error bound allows.
///
/// The rule for the sixth-order method. Over a step h the electrical part of model (1) is
/// linear in (Phi, I) for a given speed; written with complex numbers (alpha + j beta) its
/// matrix is the 2 x 2 complex
///   M = [ -alpha + j p w     alpha Lm ]
///       [ alpha beta - j p beta w   -gamma ],
/// whose eigenvalues are bounded by rho = alpha + gamma + p |w| (checked numerically for the
/// test motors over +-3000 rad/s: |lambda| <= 0.99 rho). The method's stability polynomial
/// matches e^z up to z^6; its z^7 coefficient is -1/2160 where e^z has 1/5040, so the local error
/// on such a mode is about |lambda h|^7 (1/2160 + 1/5040) = |lambda h|^7 / 1512: with
/// rho h <= 0.05 it is below 5.2e-13 of the state per step, and the mode damps what it
/// accumulates. RK4 at 10 us has |lambda h| < 0.02 for every motor of the tests (0.75 to
/// 37 kW, up to twice their speed) and a local error of |lambda h|^5 / 5! < 3e-11. tests/hal_sim/test_plant_integrator.cpp measures
/// both against RK4 at 1 us and requires the two to agree within 1e-9 of each state's scale.
///
/// The sixth-order method is used only where the right-hand side is smooth over the period:
/// a held voltage (the inverter's average), the analog feedback (2), the current-fed step. The
/// inverter's dead time (a sign of the current), the switching inverter's segments and an
/// engaged holding brake (friction stiff at 1/h of RK4's step) keep RK4.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

namespace imd::sim {

enum class PlantIntegrator {
  rk4,  ///< `substeps` RK4 steps per period
  rk6,  ///< sixth-order steps, as many as the step rule above asks
};

/// The scenario's names for the integrators (simulation.integrator).
inline constexpr std::string_view kPlantIntegratorNames[] = {"rk4", "rk6"};

inline std::string_view integrator_name(PlantIntegrator integrator) noexcept {
  return kPlantIntegratorNames[static_cast<int>(integrator)];
}

inline std::optional<PlantIntegrator> integrator_named(std::string_view name) noexcept {
  if (name == "rk4") return PlantIntegrator::rk4;
  if (name == "rk6") return PlantIntegrator::rk6;
  return std::nullopt;
}

/// The largest rho h of a sixth-order step (see above).
inline constexpr double kRk6MaxStepRadius = 0.05;

/// Sixth-order steps for a period of period_s when the electrical modes are bounded by
/// rho_per_s (alpha + gamma + p |w|).
inline int rk6_steps(double rho_per_s, double period_s) noexcept {
  const double steps = std::ceil(rho_per_s * period_s / kRk6MaxStepRadius);
  return steps < 1.0 ? 1 : int(std::min(steps, 1e6));
}

}  // namespace imd::sim
