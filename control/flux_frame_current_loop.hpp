#pragma once
/// The field-oriented controller's current loops: one PI per axis of the rotor-flux frame
/// (d along the flux, q across it) with
///   * pole-zero cancellation of the stator transient time constant 1/gamma (gains from
///     control/ifoc_design.hpp: the closed loop has one pole, at e^{-w_c T});
///   * feed-forward of what couples the axes and of the rotor's EMF, from the model
///       u_d = sigma (di_d/dt + gamma i_d - w_e i_q) - (Lm Rr / Lr^2) psi_r,
///       u_q = sigma (di_q/dt + gamma i_q + w_e i_d) + p w (Lm / Lr) psi_r,
///     so that each PI sees sigma di/dt = -sigma gamma i + u alone;
///   * anti-windup against the voltage disk: d keeps its voltage if it can, q gets what is left,
///     and each integrator tracks the voltage that can act (it takes what the disk cut off).
/// Tick context except construction.
#include <algorithm>
#include <cmath>

#include "control/frames.hpp"
#include "control/ifoc_design.hpp"
#include "control/input_disk.hpp"

namespace imd::control {

template <typename T>
struct CurrentLoopInput {
  Vec2<T> i_ref_dq_A = Vec2<T>::Zero();
  Vec2<T> i_dq_A = Vec2<T>::Zero();  ///< at the start of the period the voltage acts on
  T omega_e_rad_s = T(0);            ///< the flux frame's electrical speed
  T omega_mech_rad_s = T(0);
  T flux_Wb = T(0);                  ///< rotor flux (the controller's model)
  InputDisk<T> u_feasible_dq_V;      ///< stator voltages allowed, flux frame
};

template <typename T>
struct CurrentLoopOutput {
  Vec2<T> u_dq_V = Vec2<T>::Zero();  ///< within the disk
  bool voltage_limited = false;      ///< the PIs asked for more than the disk
};

template <typename T>
class FluxFrameCurrentLoop {
 public:
  explicit FluxFrameCurrentLoop(const IfocGains& g) noexcept
      : kp_(T(g.current_kp_V_per_A)),
        ki_(T(g.current_ki_V_per_A)),
        sigma_(T(g.sigma_H)),
        sigma_gamma_(T(g.sigma_H * g.gamma_per_s)),
        rotor_emf_(T(g.Lm_over_Lr * g.alpha_per_s)),
        Lm_over_Lr_(T(g.Lm_over_Lr)),
        p_(T(g.pole_pairs)) {}

  /// Bumpless start on a motor in steady state at zero slip with this current: the
  /// integrators hold the voltage the feed-forward leaves to them.
  void reset(const Vec2<T>& i_dq_A) noexcept { integral_V_ = sigma_gamma_ * i_dq_A; }

  CurrentLoopOutput<T> step(const CurrentLoopInput<T>& in) noexcept {
    const Vec2<T> error = in.i_ref_dq_A - in.i_dq_A;
    const T w = in.omega_e_rad_s;
    const Vec2<T> feedforward_V(
        -sigma_ * w * in.i_dq_A.y() - rotor_emf_ * in.flux_Wb,
        sigma_ * w * in.i_dq_A.x() + p_ * in.omega_mech_rad_s * Lm_over_Lr_ * in.flux_Wb);
    const Vec2<T> u_V = kp_ * error + integral_V_ + feedforward_V;
    CurrentLoopOutput<T> out;
    out.u_dq_V = limit_d_first(u_V, in.u_feasible_dq_V);
    out.voltage_limited = out.u_dq_V != u_V;
    integral_V_ += ki_ * error + (out.u_dq_V - u_V);  // tracking anti-windup
    return out;
  }

  const Vec2<T>& integral_V() const noexcept { return integral_V_; }

  /// The point of the disk that keeps u_d if it can, then as much of u_q as is left.
  static Vec2<T> limit_d_first(const Vec2<T>& u, const InputDisk<T>& disk) noexcept {
    // Inside the disk (or without one) u is its own limit, to the bit: for an off-centre disk
    // the clamps below round c + (u - c) away from u (for 13 % of random voltages inside it)
    // and would report a cut that did not happen, undoing the IFOC's speed integrator step. A
    // NaN u fails the test and takes the clamps' path, as before.
    if (disk.contains(u)) return u;
    const Vec2<T>& c = disk.center_V;
    const T r = disk.radius_V > T(0) ? disk.radius_V : T(0);
    const T d = std::clamp(u.x() - c.x(), -r, r);
    const T q_room = std::sqrt(std::max(r * r - d * d, T(0)));
    return Vec2<T>(c.x() + d, c.y() + std::clamp(u.y() - c.y(), -q_room, q_room));
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const FluxFrameCurrentLoop& old) noexcept {
    integral_V_ = old.integral_V_;
  }

 private:
  T kp_, ki_, sigma_, sigma_gamma_, rotor_emf_, Lm_over_Lr_, p_;
  Vec2<T> integral_V_ = Vec2<T>::Zero();
};

}  // namespace imd::control
