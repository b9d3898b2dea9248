#pragma once
/// Indirect field-oriented control (IFOC), the classic drive's law, as the baseline the papers'
/// laws are measured against (docs/ifoc.md). Each period:
///   1. the rotor-flux model (control/rotor_flux_model.hpp) advances with the measured current:
///      flux modulus and slip angle from the controller's rotor time constant;
///   2. a speed PI with inertia and friction feed-forward gives the torque; its integrator
///      stops while the current limit or the voltage limit keeps that torque from the motor;
///   3. flux by the magnetizing current i_d = psi_ref / Lm, the flux reference lowered to what the
///      voltage allows above base speed (control/field_weakening.hpp); torque by
///      i_q = T / (3/2 p Lm/Lr psi_r); |i| within the current limit, d first;
///   4. two PIs on the predicted current of the period the voltage acts on (the same latency
///      compensation as the other laws), with pole-zero cancellation of the stator transient
///      time constant, cross-coupling and back-EMF feed-forward, and anti-windup against the
///      voltage disk: d has priority, and each integrator tracks the voltage that can act.
/// Gains from control/ifoc_design.hpp. Works in the rotor-aligned frame AB of the drive: its
/// output is the stator voltage there. Tick context except construction.
#include <algorithm>
#include <cmath>
#include <limits>

#include "control/atan2.hpp"
#include "control/field_weakening.hpp"
#include "control/flux_frame_current_loop.hpp"
#include "control/frames.hpp"
#include "control/ifoc_design.hpp"
#include "control/input_disk.hpp"
#include "control/rotor_flux_model.hpp"
#include "control/speed_pi.hpp"

namespace imd::control {

template <typename T>
struct IfocInput {
  Vec2<T> i_now_AB_A = Vec2<T>::Zero();    ///< stator current at this tick
  Vec2<T> i_input_AB_A = Vec2<T>::Zero();  ///< predicted at the start of the input's period
  T omega_mech_rad_s = T(0);               ///< speed at the start of the input's period
  T omega_ref_rad_s = T(0);                ///< speed reference at that step
  T omega_ref_next_rad_s = T(0);           ///< and one step later
  T flux_ref_Wb = T(0);                    ///< rotor-flux modulus wanted (below base speed)
  InputDisk<T> u_feasible_AB_V;            ///< stator voltages allowed over the period
  T v_max_V = T(0);                        ///< the voltage disk's radius (field weakening)
};

template <typename T>
struct IfocOutput {
  Vec2<T> u_AB_V = Vec2<T>::Zero();      ///< stator voltage, rotor frame
  Vec2<T> i_ref_AB_A = Vec2<T>::Zero();  ///< current reference, rotor frame
  Vec2<T> i_ref_dq_A = Vec2<T>::Zero();  ///< current reference, flux frame
  T torque_ref_Nm = T(0);                ///< from the speed loop
  T torque_cmd_Nm = T(0);                ///< after the current limit
  T flux_ref_Wb = T(0);                  ///< after field weakening
  bool torque_limited = false;           ///< the current limit trimmed the torque
  bool voltage_limited = false;          ///< the PI voltage was outside the disk
  bool torque_clamped = false;           ///< the speed PI's torque limit cut its output
};

template <typename T>
class Ifoc {
 public:
  explicit Ifoc(const IfocGains& g) noexcept
      : flux_model_(g.rotor_flux_decay, g.alpha_per_s, g.Lm_H, g.sample_period_s, g.min_flux_Wb),
        speed_pi_(g.speed),
        current_loop_(g),
        Lm_(T(g.Lm_H)),
        kt_(T(g.torque_constant_Nm_per_Wb_A)),
        p_(T(g.pole_pairs)),
        J_over_T_(T(g.J_kgm2 / g.sample_period_s)),
        friction_(T(g.friction_Nms)),
        i_limit_(T(g.current_limit_A)),
        min_flux_(T(g.min_flux_Wb)),
        fw_share_(T(g.field_weakening_voltage_share)),
        fw_motor_{T(g.Rs_Ohm), T(g.Ls_H), T(g.sigma_H), T(g.Lm_H)},
        latency_ticks_(g.latency_ticks) {}

  /// Starts on a magnetized motor: the rotor flux (rotor frame) and the current flowing.
  void start(const Vec2<T>& flux_r_AB_Wb, const Vec2<T>& i_AB_A) noexcept {
    const T flux = flux_r_AB_Wb.norm();
    const T angle = flux > min_flux_ ? atan2_rad(flux_r_AB_Wb.y(), flux_r_AB_Wb.x())
                                     : atan2_rad(i_AB_A.y(), i_AB_A.x());
    flux_model_.reset(flux, angle);
    const Vec2<T> i_dq = flux_model_.frame().apply_inverse(i_AB_A);
    current_loop_.reset(i_dq);
    speed_pi_.reset();
    fw_updated_ = false;
  }

  /// One tick. Inlined into the law's adapter, its one caller: its input and output structures
  /// then stay in registers (docs/performance-compiler.md).
  [[gnu::always_inline]] IfocOutput<T> step(const IfocInput<T>& in) noexcept {
    IfocOutput<T> out;
    flux_model_.advance(flux_model_.frame().apply_inverse(in.i_now_AB_A));
    // The frame of the input's period (the latency's ticks after this one).
    const Rotation<T> frame = flux_model_.frame_ahead(latency_ticks_ - 1);
    const Vec2<T> i_dq = frame.apply_inverse(in.i_input_AB_A);
    const T flux = std::max(flux_model_.flux_Wb(), min_flux_);
    const T omega_e = p_ * in.omega_mech_rad_s + flux_model_.slip_rad_s();

    // Flux: the reference, or what the voltage allows above base speed (field weakening's
    // limit, from the last step's speed and torque current: update_field_weakening).
    fw_omega_e_ = omega_e;
    fw_i_q_ = i_dq.y();
    fw_v_ = fw_share_ * in.v_max_V;
    if (!fw_updated_) update_field_weakening();  // not updated since the last step: now
    fw_updated_ = false;
    out.flux_ref_Wb = std::max(std::min(in.flux_ref_Wb, flux_limit_Wb_), min_flux_);
    const T i_d_ref = std::min(out.flux_ref_Wb / Lm_, i_limit_);

    // Torque: speed PI with feed-forward, then the current left beside i_d.
    const T feedforward = J_over_T_ * (in.omega_ref_next_rad_s - in.omega_ref_rad_s) +
                          friction_ * in.omega_ref_next_rad_s;
    out.torque_ref_Nm = speed_pi_.step(in.omega_ref_rad_s, in.omega_mech_rad_s, feedforward);
    out.torque_clamped = speed_pi_.saturated();
    const T i_q_max = std::sqrt(std::max(i_limit_ * i_limit_ - i_d_ref * i_d_ref, T(0)));
    const T i_q_wanted = out.torque_ref_Nm / (kt_ * flux);
    const T i_q_ref = std::clamp(i_q_wanted, -i_q_max, i_q_max);
    out.torque_limited = i_q_ref != i_q_wanted;
    if (out.torque_limited) speed_pi_.undo_last_integration();
    out.torque_cmd_Nm = kt_ * flux * i_q_ref;
    out.i_ref_dq_A = Vec2<T>(i_d_ref, i_q_ref);

    CurrentLoopInput<T> loop;
    loop.i_ref_dq_A = out.i_ref_dq_A;
    loop.i_dq_A = i_dq;
    loop.omega_e_rad_s = omega_e;
    loop.omega_mech_rad_s = in.omega_mech_rad_s;
    loop.flux_Wb = flux;
    loop.u_feasible_dq_V = {frame.apply_inverse(in.u_feasible_AB_V.center_V),
                            in.u_feasible_AB_V.radius_V};
    const CurrentLoopOutput<T> u = current_loop_.step(loop);
    out.voltage_limited = u.voltage_limited;
    // The torque asked for cannot be imposed with the voltage there is: the speed integrator
    // must not wind up against the voltage limit either.
    if (u.voltage_limited && !out.torque_limited) speed_pi_.undo_last_integration();
    out.u_AB_V = frame.apply(u.u_dq_V);
    out.i_ref_AB_A = frame.apply(out.i_ref_dq_A);
    return out;
  }

  /// Field weakening's limit for the next step: what the voltage allows with the last step's
  /// torque current flowing at its speed, but never less than the flux of the most torque per
  /// volt (less flux would ask for more current and lower the limit again). A drive calls it
  /// after the PWM write, off the latency to the write: the limit is then one period late on a
  /// speed and a current that move over milliseconds. A step that finds it not called since
  /// the last step (the first one, or a caller that never does) computes it itself.
  void update_field_weakening() noexcept {
    flux_limit_Wb_ = std::max(voltage_limited_flux_Wb(fw_motor_, fw_omega_e_, fw_i_q_, fw_v_),
                              max_torque_per_volt_flux_Wb(fw_motor_, fw_omega_e_, fw_v_));
    fw_updated_ = true;
  }

  const RotorFluxModel<T>& flux_model() const noexcept { return flux_model_; }
  const SpeedPi<T>& speed_pi() const noexcept { return speed_pi_; }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const Ifoc& old) noexcept {
    flux_model_.continue_from(old.flux_model_);
    speed_pi_.continue_from(old.speed_pi_);
    current_loop_.continue_from(old.current_loop_);
    flux_limit_Wb_ = old.flux_limit_Wb_;
    fw_updated_ = old.fw_updated_;
  }

 private:
  RotorFluxModel<T> flux_model_;
  SpeedPi<T> speed_pi_;
  FluxFrameCurrentLoop<T> current_loop_;
  T Lm_, kt_, p_;
  T J_over_T_, friction_, i_limit_, min_flux_, fw_share_;
  FieldWeakeningMotor<T> fw_motor_;
  int latency_ticks_;
  T flux_limit_Wb_ = std::numeric_limits<T>::infinity();  ///< field weakening's, next step
  T fw_omega_e_ = T(0), fw_i_q_ = T(0), fw_v_ = T(0);     ///< this step's, for the next limit
  bool fw_updated_ = false;  ///< the limit was updated since the last step
};

}  // namespace imd::control
