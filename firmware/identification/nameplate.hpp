#pragma once
/// What a commissioning run starts from: the motor's nameplate, and the test levels, gains and
/// times of the standstill identification derived from it and from the board by the rules of
/// docs/identification.md. Construction only (in the design arithmetic Real).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "control/real.hpp"

namespace imd::firmware {

struct Nameplate {
  Real rated_voltage_V = 0.0;     ///< line-to-line, RMS
  Real rated_current_A = 0.0;     ///< RMS
  Real rated_frequency_Hz = 0.0;  ///< stator frequency at rated speed
  int pole_pairs = 0;
};

/// The standstill test's parameters (all currents are alpha-axis peaks).
struct IdentificationPlan {
  Real period_s = Real(1e-4);
  Real i_low_A = 0.0, i_high_A = 0.0;     ///< the two DC levels
  Real sigma_Ls_guess_H = 0.0;            ///< the transient inductance expected from the nameplate
  Real kp_Ohm = 0.0, ki_Ohm_per_s = 0.0;  ///< the current loop's PI
  Real v_limit_V = 0.0;                   ///< the loop's output limit (linear SVPWM range)
  Real hf_voltage_V = 0.0;                ///< square-wave amplitude of the sigma Ls step
  Real hf_ripple_A = 0.0;  ///< the ripple it aims at (the amplitude is cut to it once probed)
  int hf_half_period_ticks = 2;
  /// Times in ticks (plan_identification sets them from the period; these are 10 kHz's):
  int hf_ticks = 2000;     ///< length of the square-wave injection (0.2 s)
  int window_ticks = 100;  ///< the settling detector's averaging window (10 ms)
  Real max_level_s = 60.0;        ///< a level that never settles fails the run
  Real ramp_down_s = Real(0.05);  ///< current to zero at the end
};

/// The rules (docs/identification.md, "Test levels and gains"):
/// * base impedance Z_b = V_LL / (sqrt(3) I_rated); the transient inductance of a standard
///   motor is 0.1..0.2 per unit: sigma Ls ~ 0.15 Z_b / omega_rated;
/// * DC levels at 0.3 and 0.6 of the rated peak current (never above 0.75 of the board's
///   limit, which leaves room for the square wave's ripple): high enough that no phase current comes near zero, where the dead time's error
///   changes sign, and low enough not to saturate the iron;
/// * the PI's crossover omega_c = 2 pi 50 Hz on sigma Ls (Kp = sigma Ls omega_c; Ki = Kp
///   omega_c / 5): far below the sample rate, so a guess three times off stays stable, and slow
///   enough that the ADC noise barely reaches the voltage the estimates use;
/// * the square wave of the sigma Ls step makes a current ripple of 0.2 of the high level; its
///   first two periods at a quarter of the amplitude probe sigma Ls, and the amplitude is cut
///   to what gives that ripple on the probed value (a motor of lower sigma Ls than the guess
///   would otherwise take the current past the board's limit).
inline IdentificationPlan plan_identification(const Nameplate& n, Real i_max_A, Real v_bus_V,
                                              Real period_s) {
  IdentificationPlan p;
  p.period_s = period_s;
  p.hf_ticks = std::max(1, static_cast<int>(std::lround(Real(0.2) / period_s)));
  p.window_ticks = std::max(1, static_cast<int>(std::lround(Real(0.01) / period_s)));
  const Real i_rated_peak_A = std::sqrt(Real(2.0)) * n.rated_current_A;
  // The square wave rides 0.2 I2 above the level: its peak stays within 0.9 of the limit.
  const Real i_top_A = std::min(Real(0.6) * i_rated_peak_A, Real(0.75) * i_max_A);
  p.i_high_A = i_top_A;
  p.i_low_A = Real(0.5) * i_top_A;
  const Real z_base_Ohm = n.rated_voltage_V / (std::sqrt(Real(3.0)) * n.rated_current_A);
  const Real omega_rated_rad_s = 2 * std::numbers::pi_v<Real> * n.rated_frequency_Hz;
  p.sigma_Ls_guess_H = Real(0.15) * z_base_Ohm / omega_rated_rad_s;
  const Real omega_c_rad_s = Real(2.0 * std::numbers::pi * 50.0);
  p.kp_Ohm = p.sigma_Ls_guess_H * omega_c_rad_s;
  p.ki_Ohm_per_s = p.kp_Ohm * omega_c_rad_s / 5;
  p.v_limit_V = Real(0.95) * v_bus_V / std::sqrt(Real(3.0));
  const Real ripple_A = Real(0.2) * p.i_high_A;
  p.hf_ripple_A = ripple_A;
  p.hf_voltage_V =
      std::min(ripple_A * p.sigma_Ls_guess_H / (Real(p.hf_half_period_ticks) * period_s),
               Real(0.3) * p.v_limit_V);
  return p;
}

}  // namespace imd::firmware
