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
/// errors). Tick context except construction.
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

template <typename T>
class RotorResistanceMras {
 public:
  /// `motor`: the model's motor, whose Rr the estimate starts from; `nominal_Rr_Ohm`: the
  /// value the bounds min_scale and max_scale refer to (the motor record's).
  RotorResistanceMras(const MotorParameters& motor, const RotorResistanceMrasConfig& c,
                      Real nominal_Rr_Ohm) noexcept
      : period_s_(T(c.sample_period_s)),
        Lm_H_(T(motor.Lm_H)),
        Lm_over_Lr_(T(motor.Lm_H / motor.Lr_H)),
        inv_Lr_(T(1 / motor.Lr_H)),
        sigma_over_T_(T((motor.Ls_H - motor.Lm_H * motor.Lm_H / motor.Lr_H) / c.sample_period_s)),
        p_(T(motor.pole_pairs)),
        filter_(T(c.sample_period_s / filter_s(motor, c))),
        gain_(T(c.sample_period_s / convergence_s(motor, c))),
        min_tangent_(T(c.min_slip_tangent)),
        min_frequency_(T(c.min_frequency_rad_s)),
        Rr_min_Ohm_(T(c.min_scale * nominal_Rr_Ohm)),
        Rr_max_Ohm_(T(c.max_scale * nominal_Rr_Ohm)),
        inv_nominal_(T(1 / nominal_Rr_Ohm)),
        Rr_Ohm_(T(std::clamp(motor.Rr_Ohm, c.min_scale * nominal_Rr_Ohm,
                             c.max_scale * nominal_Rr_Ohm))) {}

  /// The rules' time constants for this motor (for documentation and the service loop).
  static Real filter_s(const MotorParameters& m, const RotorResistanceMrasConfig& c) noexcept {
    return c.filter_time_constant_s > 0 ? c.filter_time_constant_s : m.Lr_H / m.Rr_Ohm;
  }
  static Real convergence_s(const MotorParameters& m, const RotorResistanceMrasConfig& c) noexcept {
    return c.convergence_time_constant_s > 0 ? c.convergence_time_constant_s
                                             : 4 * m.Lr_H / m.Rr_Ohm;
  }

  T Rr_Ohm() const noexcept { return Rr_Ohm_; }
  /// The estimate over the nominal rotor resistance.
  T scale() const noexcept { return Rr_Ohm_ * inv_nominal_; }
  /// Whether the last step adapted (excited and allowed).
  bool adapting() const noexcept { return adapting_; }
  /// The slip tangent x of the filtered model, and the filtered powers (for telemetry/tests).
  T slip_tangent() const noexcept { return tangent_; }
  T q_reference_var() const noexcept { return q_ref_; }
  T q_adaptive_var() const noexcept { return q_adapt_; }
  const Vec2<T>& model_flux_AB_Wb() const noexcept { return flux_AB_Wb_; }

  /// One tick. `i_alphabeta_A`, `i_AB_A`: the current measured now (t_k) in the stator and the
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
    const T rho_T = Rr_Ohm_ * inv_Lr_ * period_s_;
    const T share = rho_T * (T(1) - rho_T * (T(0.5) - rho_T * (T(1) / T(6))));  // 1 - e^{-rho T}
    flux_AB_Wb_ += share * (Lm_H_ * T(0.5) * (i_AB_A + i_AB_last_A_) - flux_AB_Wb_);
    // Q^ over the period: i.Psi^ and i x Psi^ by the trapezoid, with the period's mean speed.
    const T along_now = i_AB_A.dot(flux_AB_Wb_), across_now = cross(i_AB_A, flux_AB_Wb_);
    const T q_adapt = Lm_over_Lr_ * T(0.5) *
                      (p_ * omega_mean_rad_s * (along_now + along_last_) -
                       Rr_Ohm_ * inv_Lr_ * (across_now + across_last_));
    const Vec2<T> i_mean_A = T(0.5) * (i_alphabeta_A + i_alphabeta_last_A_);
    const T q_ref =
        cross(i_mean_A, u_alphabeta_V) - sigma_over_T_ * cross(i_alphabeta_last_A_, i_alphabeta_A);
    q_ref_ += filter_ * (q_ref - q_ref_);
    q_adapt_ += filter_ * (q_adapt - q_adapt_);
    along_ += filter_ * (along_now - along_);
    across_ += filter_ * (-across_now - across_);  // Psi^ x i
    tangent_ = along_ > T(0) ? across_ / along_ : T(0);
    const T omega_e = p_ * omega_mech_rad_s + tangent_ * Rr_Ohm_ * inv_Lr_;
    // The filtered powers must also have been drawn above that frequency: in steady state
    // q_adapt_ = (Lm/Lr) w_e i.Psi^, and after a reversal the filters still hold the powers of
    // the slower frequencies of the last ~tau_r, near zero, whose ratio the voltage's errors
    // decide (docs/robustness.md, "Near a reversal").
    const T q_floor = min_frequency_ * Lm_over_Lr_ * along_;
    adapting_ = adapt && along_ > T(0) && std::abs(tangent_) >= min_tangent_ &&
                std::abs(omega_e) >= min_frequency_ && q_adapt_ * omega_e > T(0) &&
                std::abs(q_adapt_) >= q_floor;
    const T relative = adapting_ ? (q_ref_ - q_adapt_) / q_adapt_ : T(0);  // divides if used
    if (adapting_ && std::isfinite(relative)) {
      // The relative step, bounded: one tick moves the estimate by at most gain x 100 %. The
      // steps (gain ~ 1e-4 and less) are summed apart and applied once they reach 1e-4: in
      // float, Rr (1 + step) would round a step below 6e-8 away and stall the estimate.
      pending_ += gain_ * std::clamp(relative, T(-1), T(1));
      if (std::abs(pending_) >= T(1e-4)) {
        Rr_Ohm_ = std::clamp(Rr_Ohm_ * (T(1) + pending_), Rr_min_Ohm_, Rr_max_Ohm_);
        pending_ = T(0);
      }
    }
    if (!all_finite(q_ref_, q_adapt_, along_, across_, flux_AB_Wb_.x(), flux_AB_Wb_.y())) {
      reset_filters();  // a non-finite input must not stay in the filters
    }
    i_AB_last_A_ = i_AB_A;
    i_alphabeta_last_A_ = i_alphabeta_A;
    along_last_ = along_now;
    across_last_ = across_now;
  }

  /// Carries the estimate and the filters over from the tracker of the model this one replaces
  /// (the same motor but for Rr).
  void continue_from(const RotorResistanceMras& old) noexcept {
    Rr_Ohm_ = std::clamp(old.Rr_Ohm_, Rr_min_Ohm_, Rr_max_Ohm_);
    flux_AB_Wb_ = old.flux_AB_Wb_;
    i_AB_last_A_ = old.i_AB_last_A_;
    i_alphabeta_last_A_ = old.i_alphabeta_last_A_;
    along_last_ = old.along_last_;
    across_last_ = old.across_last_;
    q_ref_ = old.q_ref_;
    q_adapt_ = old.q_adapt_;
    along_ = old.along_;
    across_ = old.across_;
    tangent_ = old.tangent_;
    adapting_ = old.adapting_;
    pending_ = old.pending_;
  }

 private:
  void reset_filters() noexcept {
    flux_AB_Wb_ = i_AB_last_A_ = i_alphabeta_last_A_ = Vec2<T>::Zero();
    along_last_ = across_last_ = q_ref_ = q_adapt_ = along_ = across_ = tangent_ = pending_ = T(0);
  }

  /// a x b = a_x b_y - a_y b_x (the reactive power of a current and a voltage).
  static T cross(const Vec2<T>& a, const Vec2<T>& b) noexcept {
    return a.x() * b.y() - a.y() * b.x();
  }

  T period_s_, Lm_H_, Lm_over_Lr_, inv_Lr_, sigma_over_T_, p_, filter_, gain_;
  T min_tangent_, min_frequency_, Rr_min_Ohm_, Rr_max_Ohm_, inv_nominal_;
  T Rr_Ohm_;
  Vec2<T> flux_AB_Wb_ = Vec2<T>::Zero();
  Vec2<T> i_AB_last_A_ = Vec2<T>::Zero(), i_alphabeta_last_A_ = Vec2<T>::Zero();
  T along_last_ = T(0), across_last_ = T(0);  ///< i.Psi^ and i x Psi^ at t_{k-1}
  T q_ref_ = T(0), q_adapt_ = T(0), along_ = T(0), across_ = T(0);
  T tangent_ = T(0);
  T pending_ = T(0);  ///< relative steps not yet applied to Rr_Ohm_
  bool adapting_ = false;
};

}  // namespace imd::control
