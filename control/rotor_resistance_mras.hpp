#pragma once
/// Online estimate of the rotor resistance by a reactive-power model-reference adaptive system
/// (MRAS). The reactive power the magnetizing branch draws is measured two ways:
///
///   reference: Q = i x u - sigma i x di/dt    (stator frame; no Rs in it)
///   adaptive:  Q^ = (Lm/Lr) i x dPsi^/dt      (Psi^ from the current model with Rr^)
///
/// where x is the planar cross product. In the rotor-aligned frame the current model is
/// dPsi^/dt = rho^ (Lm i - Psi^), rho^ = Rr^/Lr, so that Q^ = (Lm/Lr)(p w i.Psi^ - rho^ i x Psi^).
/// In steady state Q^ = (Lm^2/Lr) w_e |i|^2 / (1 + x^2) with x = w_slip/rho^ (the tangent of the
/// angle between current and model flux), which grows with rho^: the estimate moves by
///   d rho^/dt = rho^ (Q - Q^) / (tau_c Q^),
/// and near the true value its relative error decays at the rate 2 x^2/(1 + x^2) / tau_c
/// (docs/robustness.md). At no load the slip is zero, x = 0, Q^ does not depend on rho^, and
/// the estimate is frozen: below |x| = min_slip_tangent, and below min_frequency_rad_s of the
/// stator frequency, now or in the filtered powers (Q is then too small against the voltage's
/// errors). The powers are summed every tick and filtered, judged and adapted on once per block
/// of ticks (block_ticks(): a thirty-second of the shorter time constant, at most 64 ticks).
/// Tick context except construction.
#include <algorithm>
#include <cmath>

#include "control/frames.hpp"
#include "control/motor_parameters.hpp"
#include "control/real.hpp"

namespace imd::control {

struct RotorResistanceMrasConfig {
  Real sample_period_s = Real(1e-4);
  /// Time constant of the adaptation at x = 1 (0: four rotor time constants, so that the
  /// model flux's own transients, which last ~tau_r, have settled within each step).
  Real convergence_time_constant_s = 0.0;
  /// Both powers are low-passed alike over this time (0: one rotor time constant).
  Real filter_time_constant_s = 0.0;
  Real min_slip_tangent = 0.25;  ///< |x| below: frozen (no excitation)
  Real min_frequency_rad_s = Real(2.0 * 3.14159265358979 * 2.0);  ///< |w_e| below: frozen
  Real min_scale = Real(0.3), max_scale = Real(3.0);  ///< the estimate stays within these x Rr
};

/// Ticks summed before the filters, the tests and the adaptation run once on their means: a
/// thirty-second of the shorter of the filter's and the adaptation's time constants. The mean
/// delays the powers by half a block, tau / 64, which costs the adaptation's loop (crossover
/// 1 / (4 tau_r)) a quarter of a degree of phase; within a block, where a filter run every tick
/// would weigh the ticks by (1 - T/tau)^j, the mean weighs them alike (1.5 % apart at most, as
/// N T / tau <= 1/32). At most 64 ticks, whose float sums keep 2^-18 of their terms.
inline int mras_block_ticks(Real time_constant_s, Real sample_period_s) noexcept {
  const Real ticks = time_constant_s / (32 * sample_period_s);
  return ticks >= 64 ? 64 : (ticks >= 1 ? static_cast<int>(ticks) : 1);
}

template <typename T>
class RotorResistanceMras {
  /// What the tracker learns as it runs, and a tracker that takes over carries on from.
  struct State {
    Vec2<T> flux_AB_Wb = Vec2<T>::Zero();  ///< the current model's flux
    Vec2<T> i_AB_last_A = Vec2<T>::Zero(), i_alphabeta_last_A = Vec2<T>::Zero();
    T along_last = T(0), across_last = T(0);  ///< i.Psi^ and i x Psi^ at t_{k-1}
    /// This block's sums: 2 Q, 2 Q^ Lr/Lm, i.Psi^ and i x Psi^ over its ticks so far.
    T sum_q_ref = T(0), sum_q_adapt = T(0), sum_along = T(0), sum_across = T(0);
    int in_block = 0;
    bool block_adapts = true;  ///< allowed on each of the block's ticks so far
    T q_ref = T(0), q_adapt = T(0), along = T(0), across = T(0);  ///< filtered
    T tangent = T(0);
    T pending = T(0);  ///< relative steps not yet applied to Rr_Ohm_
    bool adapting = false;
  };
  struct Rates {
    int block;  ///< ticks
    T filter;   ///< the filters' share per block
    T gain;     ///< the adaptation's per tick
  };

 public:
  /// `motor`: the model's motor, whose Rr the estimate starts from; `nominal_Rr_Ohm`: the
  /// value the bounds min_scale and max_scale refer to (the motor record's).
  RotorResistanceMras(const MotorParameters& motor, const RotorResistanceMrasConfig& c,
                      Real nominal_Rr_Ohm) noexcept
      : period_s_(T(c.sample_period_s)),
        half_Lm_H_(T(motor.Lm_H / 2)),
        Lm_over_Lr_(T(motor.Lm_H / motor.Lr_H)),
        inv_Lr_(T(1 / motor.Lr_H)),
        two_sigma_over_T_(
            T(2 * (motor.Ls_H - motor.Lm_H * motor.Lm_H / motor.Lr_H) / c.sample_period_s)),
        p_(T(motor.pole_pairs)),
        rates_(rates(motor, c)),
        min_tangent_(T(c.min_slip_tangent)),
        min_frequency_(T(c.min_frequency_rad_s)),
        Rr_min_Ohm_(T(c.min_scale * nominal_Rr_Ohm)),
        Rr_max_Ohm_(T(c.max_scale * nominal_Rr_Ohm)),
        inv_nominal_(T(1 / nominal_Rr_Ohm)),
        Rr_Ohm_(T(
            std::clamp(motor.Rr_Ohm, c.min_scale * nominal_Rr_Ohm, c.max_scale * nominal_Rr_Ohm))) {
    set_current_model();
  }

  /// The rules' time constants for this motor (for documentation and the service loop).
  static Real filter_s(const MotorParameters& m, const RotorResistanceMrasConfig& c) noexcept {
    return c.filter_time_constant_s > 0 ? c.filter_time_constant_s : m.Lr_H / m.Rr_Ohm;
  }
  static Real convergence_s(const MotorParameters& m, const RotorResistanceMrasConfig& c) noexcept {
    return c.convergence_time_constant_s > 0 ? c.convergence_time_constant_s
                                             : 4 * m.Lr_H / m.Rr_Ohm;
  }

  /// Ticks per block of the filters and the adaptation (mras_block_ticks()).
  int block_ticks() const noexcept { return rates_.block; }
  T Rr_Ohm() const noexcept { return Rr_Ohm_; }
  /// The estimate over the nominal rotor resistance.
  T scale() const noexcept { return Rr_Ohm_ * inv_nominal_; }
  /// Whether the last block adapted (excited, and allowed on each of its ticks).
  bool adapting() const noexcept { return s_.adapting; }
  /// The slip tangent x of the filtered model, and the filtered powers (for telemetry/tests).
  T slip_tangent() const noexcept { return s_.tangent; }
  T q_reference_var() const noexcept { return s_.q_ref; }
  T q_adaptive_var() const noexcept { return s_.q_adapt; }
  const Vec2<T>& model_flux_AB_Wb() const noexcept { return s_.flux_AB_Wb; }

  /// One tick: its powers summed into the block, which ends on every block_ticks()-th tick.
  /// `i_alphabeta_A`, `i_AB_A`: the current measured now (t_k) in the stator and the
  /// rotor-aligned frame; `omega_mech_rad_s`: the speed estimate now, for the frequency tests;
  /// `omega_mean_rad_s`: the mean speed over [t_{k-1}, t_k] as measured (the encoder's counts
  /// over the period), for Q^; `u_alphabeta_V`: the stator voltage that acted over
  /// [t_{k-1}, t_k]; `adapt`: the drive runs a law (the estimate may move).
  ///
  /// Q^'s speed term is p w i.Psi^, so a speed off by dw makes Q^ off by dw / w_e: an estimate
  /// that lags the rotor after a load step (its model expects the old load) by 8 rad/s at
  /// 20 rad/s put 40 % into Q^ for 10 ms, which the filters held for a rotor time constant and
  /// the estimate then adapted on (docs/robustness.md, "A measured speed"). The counts over the
  /// period give its mean speed to one count, and the filters' average over tau_r, to one count
  /// over tau_r.
  void step(const Vec2<T>& i_alphabeta_A, const Vec2<T>& i_AB_A, T omega_mech_rad_s,
            T omega_mean_rad_s, const Vec2<T>& u_alphabeta_V, bool adapt) noexcept {
    // The current model over [t_{k-1}, t_k], the current taken as its mean over the period.
    s_.flux_AB_Wb += share_ * (half_Lm_H_ * (i_AB_A + s_.i_AB_last_A) - s_.flux_AB_Wb);
    // Q^ over the period: i.Psi^ and i x Psi^ by the trapezoid, with the period's mean speed;
    // Q likewise from the mean current (both summed without their common factors, applied
    // once per block).
    const T along_now = i_AB_A.dot(s_.flux_AB_Wb), across_now = cross(i_AB_A, s_.flux_AB_Wb);
    s_.sum_q_adapt +=
        p_ * omega_mean_rad_s * (along_now + s_.along_last) - rho_ * (across_now + s_.across_last);
    s_.sum_q_ref += cross(i_alphabeta_A + s_.i_alphabeta_last_A, u_alphabeta_V) -
                    two_sigma_over_T_ * cross(s_.i_alphabeta_last_A, i_alphabeta_A);
    s_.sum_along += along_now;
    s_.sum_across += across_now;
    s_.block_adapts = s_.block_adapts && adapt;
    s_.i_AB_last_A = i_AB_A;
    s_.i_alphabeta_last_A = i_alphabeta_A;
    s_.along_last = along_now;
    s_.across_last = across_now;
    if (++s_.in_block >= rates_.block) end_block(omega_mech_rad_s);
  }

  /// Carries the estimate and the filters over from the tracker of the model this one replaces
  /// (the same motor but for Rr).
  [[gnu::noinline]] void continue_from(const RotorResistanceMras& old) noexcept {
    Rr_Ohm_ = std::clamp(old.Rr_Ohm_, Rr_min_Ohm_, Rr_max_Ohm_);
    s_ = old.s_;  // a block longer than this one's ends at the next tick
    set_current_model();
  }

 private:
  /// The block's means through the filters, the tests of excitation and the adaptation.
  [[gnu::always_inline]] void end_block(T omega_mech_rad_s) noexcept {
    // The block's ticks: block_ticks(), or more once after a swap to a shorter block.
    const T ticks = T(s_.in_block), per_tick = T(1) / ticks;
    const T q_ref = T(0.5) * per_tick * s_.sum_q_ref;
    const T q_adapt = Lm_over_Lr_ * T(0.5) * per_tick * s_.sum_q_adapt;
    s_.q_ref += rates_.filter * (q_ref - s_.q_ref);
    s_.q_adapt += rates_.filter * (q_adapt - s_.q_adapt);
    s_.along += rates_.filter * (per_tick * s_.sum_along - s_.along);
    s_.across += rates_.filter * (-per_tick * s_.sum_across - s_.across);  // Psi^ x i
    s_.tangent = s_.along > T(0) ? s_.across / s_.along : T(0);
    const T omega_e = p_ * omega_mech_rad_s + s_.tangent * rho_;
    // The filtered powers must also have been drawn above that frequency: in steady state
    // the filtered Q^ = (Lm/Lr) w_e i.Psi^, and after a reversal the filters still hold the
    // powers of the slower frequencies of the last ~tau_r, near zero, whose ratio the voltage's
    // errors decide (docs/robustness.md, "Near a reversal").
    const T q_floor = min_frequency_ * Lm_over_Lr_ * s_.along;
    s_.adapting = s_.block_adapts && s_.along > T(0) && std::abs(s_.tangent) >= min_tangent_ &&
                  std::abs(omega_e) >= min_frequency_ && s_.q_adapt * omega_e > T(0) &&
                  std::abs(s_.q_adapt) >= q_floor;
    const T relative =
        s_.adapting ? (s_.q_ref - s_.q_adapt) / s_.q_adapt : T(0);  // divides if used
    if (s_.adapting && std::isfinite(relative)) {
      // The relative step, bounded: one tick moves the estimate by at most gain x 100 %. The
      // steps (gain ~ 1e-4 a tick and less) are summed apart and applied once they reach 1e-4:
      // in float, Rr (1 + step) would round a step below 6e-8 away and stall the estimate.
      s_.pending += ticks * rates_.gain * std::clamp(relative, T(-1), T(1));
      if (std::abs(s_.pending) >= T(1e-4)) {
        Rr_Ohm_ = std::clamp(Rr_Ohm_ * (T(1) + s_.pending), Rr_min_Ohm_, Rr_max_Ohm_);
        s_.pending = T(0);
        set_current_model();
      }
    }
    if (!all_finite(s_.q_ref, s_.q_adapt, s_.along, s_.across, s_.flux_AB_Wb.x(),
                    s_.flux_AB_Wb.y())) {
      reset_filters();  // a non-finite input must not stay in the filters
    }
    s_.sum_q_ref = s_.sum_q_adapt = s_.sum_along = s_.sum_across = T(0);
    s_.in_block = 0;
    s_.block_adapts = true;
  }

  /// The block's length, the filters' share per block (the per-tick share T / tau_f applied
  /// block times over, 1 - (1 - T / tau_f)^block, by products: no exponential in the image)
  /// and the adaptation's gain per tick, T / tau_c. Not inlined: built once per model.
  [[gnu::noinline]] static Rates rates(const MotorParameters& m,
                                       const RotorResistanceMrasConfig& c) noexcept {
    const Real tau_f_s = filter_s(m, c), tau_c_s = convergence_s(m, c);
    Rates r;
    r.block = mras_block_ticks(std::min(tau_f_s, tau_c_s), c.sample_period_s);
    Real kept = 1;
    for (int k = 0; k < r.block; ++k) kept *= 1 - c.sample_period_s / tau_f_s;
    r.filter = T(1 - kept);
    r.gain = T(c.sample_period_s / tau_c_s);
    return r;
  }

  /// The current model's constants on the estimate: rho^ = Rr^/Lr and the share 1 - e^{-rho^ T}.
  [[gnu::noinline]] void set_current_model() noexcept {  // once per model and per Rr step
    rho_ = Rr_Ohm_ * inv_Lr_;
    const T rho_T = rho_ * period_s_;
    share_ = rho_T * (T(1) - rho_T * (T(0.5) - rho_T * (T(1) / T(6))));  // 1 - e^{-rho T}
  }

  void reset_filters() noexcept { s_ = State{}; }

  /// a x b = a_x b_y - a_y b_x (the reactive power of a current and a voltage).
  static T cross(const Vec2<T>& a, const Vec2<T>& b) noexcept {
    return a.x() * b.y() - a.y() * b.x();
  }

  T period_s_, half_Lm_H_, Lm_over_Lr_, inv_Lr_, two_sigma_over_T_, p_;
  Rates rates_;
  T min_tangent_, min_frequency_, Rr_min_Ohm_, Rr_max_Ohm_, inv_nominal_;
  T Rr_Ohm_;
  T rho_ = T(0), share_ = T(0);  ///< of the current model, on Rr_Ohm_ (set_current_model())
  State s_;
};

}  // namespace imd::control
