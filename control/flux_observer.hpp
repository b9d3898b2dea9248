#pragma once
/// Rotor-flux observer of paper 000, Section IV: a copy of the flux row of the exact model,
///   Phi^_{k+1} = a11 Phi^_k + a12 I~_k + b1 v~_k,
/// driven by the measured current and the input actually applied. Its error obeys
/// e_{k+1} = a11 e_k with 0 < a11 < 1 (docs/derivations.md). Tick context.
#include "control/voltage_fed_model.hpp"
#include "control/frames.hpp"

namespace imd::control {

template <typename T>
class FluxObserver {
 public:
  explicit FluxObserver(const VoltageFedCoefficients& c) noexcept
      : a11_(T(c.a11)), a12_(T(c.a12)), b1_(T(c.b1)) {}

  const Vec2<T>& flux_r_AB_Wb() const noexcept { return flux_; }
  void reset(const Vec2<T>& flux_r_AB_Wb = Vec2<T>::Zero()) noexcept { flux_ = flux_r_AB_Wb; }

  /// Advances the estimate from step k to k+1 with I~_k and the applied v~_k.
  void update(const Vec2<T>& i_s_AB_A, const Vec2<T>& v_AB_V) noexcept {
    flux_ = a11_ * flux_ + a12_ * i_s_AB_A + b1_ * v_AB_V;
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const FluxObserver& old) noexcept {
    flux_ = old.flux_;
  }

 private:
  T a11_, a12_, b1_;
  Vec2<T> flux_ = Vec2<T>::Zero();
};

}  // namespace imd::control
