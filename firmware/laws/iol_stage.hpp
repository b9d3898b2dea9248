#pragma once
/// The current-fed controller of paper 001 inside the 10 kHz tick: every T0 (a whole number of
/// ticks) the input-output linearizing law computes the rotor-frame current of the next T0
/// period from the stator flux and the current held now; in between, the current command is
/// held (the zero-order hold in the rotor frame that paper 001 assumes). The torque reference
/// v1 comes from the reference or an outer speed PI; v2 from (21) or the outer flux loop.
/// Tick context except the constructor.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "control/current_fed_model.hpp"
#include "control/current_reach.hpp"
#include "control/field_weakening.hpp"
#include "control/flux_outer_loop.hpp"
#include "control/frames.hpp"
#include "control/iol.hpp"
#include "control/motor_parameters.hpp"
#include "control/speed_pi.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/reference_source.hpp"

namespace imd::firmware {

template <typename T>
struct IolTickResult {
  control::Vec2<T> i_cmd_AB_A = control::Vec2<T>::Zero();   ///< current to command this tick
  control::Vec2<T> i_held_AB_A = control::Vec2<T>::Zero();  ///< current the law assumes now
  bool boundary = false;                                    ///< the law ran this tick
  control::IolStatus status = control::IolStatus::ok;
  T torque_ref_Nm = T(0), torque_cmd_Nm = T(0);  ///< v1 before and after the guard
  T y2_ref = T(0), y2 = T(0);                    ///< v2, and y2(k) from the flux estimates
  T flux2_s_Wb2 = T(0);                          ///< |phi_s|^2 at this boundary
  bool torque_limited = false;
  /// The torque of the period in force was cut: by the speed PI's torque limit or by the
  /// law's guard (every tick, from the boundary that decided it).
  bool torque_held_back = false;
};

template <typename T>
class IolStage {
 public:
  /// `tick_model`: the voltage-fed model at the sample period, on which the current loop
  /// makes the law's current steps.
  IolStage(const control::MotorParameters& motor, const DriveConfig& config,
           const control::VoltageFedCoefficients& tick_model)
      : coefficients_(control::discretize_current_fed<T>(motor, config.iol_period_s)),
        law_(coefficients_, control::IolConfig{}),
        reach_(motor, tick_model),
        flux_loop_(coefficients_.flux_decay,
                   control::place_flux_outer_loop(coefficients_.flux_decay, config.iol_period_s,
                                                  config.flux_loop_time_constant_s)),
        speed_pi_(control::design_speed_pi(motor.J_kgm2, config.speed_loop_bandwidth_rad_s,
                                           config.torque_limit_Nm, config.iol_period_s)),
        ticks_per_period_(
            static_cast<int>(std::lround(config.iol_period_s / config.sample_period_s))),
        lead_ticks_(config.current_response_ticks + config.pwm_latency_ticks),
        reach_ticks_(std::max(1, ticks_per_period_ - lead_ticks_ + 1)),
        current_limit_A_(T(config.current_margin * config.i_max_A)),
        current_imposed_(config.current_response_ticks == 0),
        outer_speed_loop_(config.outer_speed_loop),
        outer_flux_loop_(config.outer_flux_loop),
        sigma_H_(T(motor.Ls_H - motor.Lm_H * motor.Lm_H / motor.Lr_H)),
        Lm_over_Lr_(T(motor.Lm_H / motor.Lr_H)),
        p_(T(motor.pole_pairs)),
        one_minus_flux_decay_(T(1) - T(coefficients_.flux_decay)) {}

  const control::CurrentFedCoefficients& coefficients() const noexcept { return coefficients_; }
  int ticks_per_period() const noexcept { return ticks_per_period_; }

  /// Starts the law with this current held (the magnetizing current).
  void start(const control::Vec2<T>& i_held_AB_A) noexcept {
    i_held_ = i_next_ = i_held_AB_A;
    phase_ = 0;
    flux_s_before_.setZero();
    flux_loop_.reset();
    speed_pi_.reset();
    torque_held_back_ = false;
  }

  /// One tick while running. `flux_r_AB_Wb`, `omega` and `i_est_AB_A` are the estimates at
  /// this tick; `ref_next` is the reference for the next T0 boundary; `v_max_V` the stator
  /// voltage the modulation reaches (+inf without a limit). Inlined into the law's adapter, its
  /// one caller (docs/performance-compiler.md).
  [[gnu::always_inline]] IolTickResult<T> tick(const control::Vec2<T>& flux_r_AB_Wb,
                                               T omega_mech_rad_s, const Reference<T>& ref_next,
                                               T v_max_V,
                                               const control::Vec2<T>& i_est_AB_A) noexcept {
    IolTickResult<T> r;
    // The tick's place in the period, counted and wrapped (no 64-bit modulo in the tick).
    const int phase = phase_;
    phase_ = phase + 1 == ticks_per_period_ ? 0 : phase + 1;
    if (phase == 0) {
      // A boundary: the current computed one period ago, u(k-1) = i(t_k), is imposed now and
      // held until the next boundary; the law computes u(k) = i(t_{k+1}) (augmented model (19)).
      i_held_ = i_next_;
      r.boundary = true;
    }
    // u(k) is known a whole period ahead: it is commanded early enough for the current to be
    // there at the next boundary, 1 + latency ticks early for the deadbeat current loop (which
    // reaches its target one tick after it acts), latency ticks for an ideal current source.
    r.i_held_AB_A = i_held_;
    r.torque_held_back = torque_held_back_;
    r.i_cmd_AB_A = (!r.boundary && ticks_per_period_ - phase <= lead_ticks_) ? i_next_ : i_held_;
    if (!r.boundary) return r;
    // The stator flux just after the current stepped to the held value (15).
    // The current that flows now: the one held, where the power stage imposes it; the
    // estimate, where a current loop makes it and may fall short (on the voltage limit, a
    // command of tens of amperes in a fast transient does not arrive).
    const control::Vec2<T>& i_now = current_imposed_ ? i_held_ : i_est_AB_A;
    const control::Vec2<T> flux_s = sigma_H_ * i_now + Lm_over_Lr_ * flux_r_AB_Wb;
    r.flux2_s_Wb2 = flux_s.squaredNorm();
    r.y2 = law_.y2(flux_s, flux_s_before_);
    flux_s_before_ = flux_s;
    r.torque_ref_Nm = outer_speed_loop_
                          ? speed_pi_.step(ref_next.omega_mech_rad_s, omega_mech_rad_s)
                          : ref_next.torque_Nm;
    const T flux2_ref =
        std::min(ref_next.stator_flux2_Wb2, voltage_limited_flux2_Wb2(omega_mech_rad_s, v_max_V));
    r.y2_ref = outer_flux_loop_ ? flux_loop_.step(flux2_ref, r.flux2_s_Wb2)
                                : one_minus_flux_decay_ * flux2_ref;  // (21)
    // The current loop starts the step to u(k) from the held current one tick before the next
    // boundary; u(k) must be there before u(k + 1) is commanded, reach_ticks_ later. An ideal
    // current source makes any step.
    const control::CurrentDisk<T> reach =
        current_imposed_
            ? control::CurrentDisk<T>{}
            : control::within_current_limit(
                  reach_.disk(flux_r_AB_Wb, i_held_, omega_mech_rad_s, v_max_V, reach_ticks_),
                  current_limit_A_);
    const control::IolOutput<T> out =
        law_.step({flux_s, i_held_, r.torque_ref_Nm, r.y2_ref, reach});
    r.status = out.status;
    r.torque_cmd_Nm = out.torque_cmd_Nm;
    r.torque_limited = out.torque_limited;
    if (out.torque_limited && outer_speed_loop_) speed_pi_.undo_last_integration();
    torque_held_back_ = out.torque_limited || (outer_speed_loop_ && speed_pi_.saturated());
    i_next_ = out.i_next_AB_A;
    return r;
  }

  /// Field weakening by the 1/w law: the squared stator flux whose back-EMF p |w| |phi_s| fits
  /// the share of v_max every law uses (control/field_weakening.hpp). With Rs neglected this
  /// is also the flux of the most torque the voltage allows: the pull-out torque grows as
  /// |phi_s|^2. Neither the Rs drop nor the slip enters. The law's held current, from which
  /// both would come, is a command that the current loop may not reach (tens of amperes in a
  /// fast transient), and taking the Rs drop off would lower the flux where the current is
  /// high, at low speed, and ask for still more current. Both are left to the margin, and the
  /// `limited` report says when the voltage still runs out. +inf without a voltage limit or at
  /// standstill.
  T voltage_limited_flux2_Wb2(T omega_mech_rad_s, T v_max_V) const noexcept {
    const T omega_e = std::abs(p_ * omega_mech_rad_s);
    if (!(v_max_V < std::numeric_limits<T>::infinity()) || !(omega_e > T(0))) {
      return std::numeric_limits<T>::infinity();
    }
    const T flux_s = T(control::kFieldWeakeningVoltageShare) * v_max_V / omega_e;
    return flux_s * flux_s;
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const IolStage& old) noexcept {
    flux_loop_.continue_from(old.flux_loop_);
    speed_pi_.continue_from(old.speed_pi_);
    i_held_ = old.i_held_;
    i_next_ = old.i_next_;
    flux_s_before_ = old.flux_s_before_;
    phase_ = old.phase_;
    torque_held_back_ = old.torque_held_back_;
  }

 private:
  control::CurrentFedCoefficients coefficients_;
  control::Iol<T> law_;
  control::CurrentReach<T> reach_;
  control::FluxOuterLoop<T> flux_loop_;
  control::SpeedPi<T> speed_pi_;
  int ticks_per_period_;
  int lead_ticks_;  ///< ticks before a boundary at which u(k) is commanded
  /// Ticks of voltage the current loop has for the step to u(k): from the tick before the
  /// boundary until u(k + 1) is commanded, lead_ticks_ before the next one.
  int reach_ticks_;
  T current_limit_A_;     ///< what the current loop plans within (+inf: no limit)
  bool current_imposed_;  ///< an ideal current source: the held current is the current
  bool outer_speed_loop_, outer_flux_loop_;
  T sigma_H_, Lm_over_Lr_;
  T p_;
  T one_minus_flux_decay_;  ///< 1 - e^{-eta T0}, in T (the tick converts nothing)
  control::Vec2<T> i_held_ = control::Vec2<T>::Zero();  ///< imposed over this period, u(k-1)
  control::Vec2<T> i_next_ = control::Vec2<T>::Zero();  ///< for the next period, u(k)
  control::Vec2<T> flux_s_before_ = control::Vec2<T>::Zero();
  int phase_ = 0;  ///< ticks since the last T0 boundary, 0 at a boundary's tick
  bool torque_held_back_ = false;
};

}  // namespace imd::firmware
