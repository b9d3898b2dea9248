#pragma once
/// The indirect field-oriented controller's rotor-flux model (the "current model"): the rotor
/// flux psi_r along d of the frame it defines, driven by the stator current in that frame,
///   d psi_r / dt = (Lm i_d - psi_r) / tau_r,      w_slip = Lm i_q / (tau_r psi_r),
/// with the controller's rotor time constant tau_r = Lr / Rr. The frame's angle is kept relative
/// to the rotor (the rotor-aligned frame AB of the drive), so it advances by the slip alone; the
/// encoder's electrical angle p theta, which the modulate stage adds, completes the flux angle
/// p theta + theta_slip of the stationary frame. Exact over a period for a current held over
/// it. Tick context except construction.
#include <algorithm>

#include "control/encoder_observer.hpp"
#include "control/frames.hpp"
#include "control/real.hpp"

namespace imd::control {

template <typename T>
class RotorFluxModel {
 public:
  /// `flux_decay` = e^{-T / tau_r}, `alpha_per_s` = 1 / tau_r; the slip divides by at least
  /// `min_flux_Wb`.
  RotorFluxModel(Real flux_decay, Real alpha_per_s, Real Lm_H, Real period_s,
                 Real min_flux_Wb) noexcept
      : decay_(T(flux_decay)),
        alpha_Lm_(T(alpha_per_s * Lm_H)),
        Lm_(T(Lm_H)),
        period_s_(T(period_s)),
        min_flux_Wb_(T(min_flux_Wb)) {}

  /// Starts from a flux of this modulus at this angle (rotor frame).
  void reset(T flux_Wb, T angle_rad) noexcept {
    flux_Wb_ = flux_Wb;
    angle_rad_ = wrap_pi(angle_rad);
    frame_ = Rotation<T>::from_angle(angle_rad_);
    slip_rad_s_ = T(0);
  }

  /// The frame now: e^{angle J} takes flux-frame (d, q) vectors to the rotor frame. Evaluated
  /// once per change of the angle (in advance), so that the tick, which asks for it again after
  /// the advance (frame_ahead(0) with one tick of latency) and before the next, pays for one
  /// cosine and sine per period.
  const Rotation<T>& frame() const noexcept { return frame_; }
  /// The frame `ticks` periods ahead at the present slip.
  Rotation<T> frame_ahead(int ticks) const noexcept {
    if (ticks == 0) return frame_;
    return Rotation<T>::from_angle(angle_rad_ + T(ticks) * slip_rad_s_ * period_s_);
  }

  /// Advances one period with the stator current i_dq (flux frame) held over it.
  void advance(const Vec2<T>& i_dq_A) noexcept {
    const T flux = std::max(flux_Wb_, min_flux_Wb_);
    slip_rad_s_ = alpha_Lm_ * i_dq_A.y() / flux;
    angle_rad_ = wrap_pi(angle_rad_ + slip_rad_s_ * period_s_);
    frame_ = Rotation<T>::from_angle(angle_rad_);
    flux_Wb_ = decay_ * flux_Wb_ + (T(1) - decay_) * Lm_ * i_dq_A.x();
  }

  T flux_Wb() const noexcept { return flux_Wb_; }
  T slip_rad_s() const noexcept { return slip_rad_s_; }  ///< electrical
  T angle_rad() const noexcept { return angle_rad_; }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const RotorFluxModel& old) noexcept {
    flux_Wb_ = old.flux_Wb_;
    angle_rad_ = old.angle_rad_;
    frame_ = old.frame_;
    slip_rad_s_ = old.slip_rad_s_;
  }

 private:
  T decay_, alpha_Lm_, Lm_, period_s_, min_flux_Wb_;
  T flux_Wb_ = T(0), angle_rad_ = T(0), slip_rad_s_ = T(0);
  Rotation<T> frame_;  ///< of angle_rad_
};

}  // namespace imd::control
