#pragma once
/// Outer loop of the stator flux (paper 001, Fig. 5). The input-output linearization makes
/// y2(k+1) = v2(k), and y2(k) ~ F(k) - e F(k-1) with F = |phi_s|^2 and e = e^{-eta T0} (the
/// paper's design assumption), so from v2 to F the loop sees F(k+1) = e F(k) + v2(k): a pole at
/// e, close to 1 (0.998 for the 37 kW motor at 1 ms). The loop adds to the feed-forward
/// (1 - e) F_ref of (21) a PI on F_ref - F:
///   v2 = (1 - e) F_ref + Kp err + I,   I <- I + Ki err.
/// The closed loop (F, I) has the characteristic polynomial z^2 - (1 + e - Kp) z + (e - Kp + Ki);
/// a double pole at z_f = exp(-T0 / tau) gives Kp = 1 + e - 2 z_f and Ki = (1 - z_f)^2. The
/// integrator removes what (21) leaves: y2 = F (cos(w_slip T0) - e) in steady state.
///
/// The design relation holds for small changes only: y2(k+1) = |phi_s(k+1)| |phi_s(k)| - e F(k)
/// for aligned fluxes, so a large v2 at a small flux multiplies the flux (from F = 0.01 Wb^2 a
/// linear v2 of 0.19 gives F = 4 Wb^2). The loop therefore takes the F(k+1) its linear design
/// intends, F_i = e F + v2_lin, and sends the v2 that gives it exactly,
/// v2 = sqrt(F) sqrt(F_i) - e F; at equilibrium the two are the same. F_i is floored at e^2 F
/// (the flux may shrink by e per period, as with no current): v2 >= 0 then, and the law's
/// flux-only command never points the stator flux away from the rotor flux.
/// Tick context except the constructor.
#include <cmath>

#include "control/real.hpp"

namespace imd::control {

struct FluxOuterLoopGains {
  Real kp = 0.0;
  Real ki = 0.0;
};

/// Gains for a double closed-loop pole at exp(-T0 / time_constant_s).
inline FluxOuterLoopGains place_flux_outer_loop(Real flux_decay, Real T0_s, Real time_constant_s) {
  const Real z = std::exp(-T0_s / time_constant_s);
  return {1 + flux_decay - 2 * z, (1 - z) * (1 - z)};
}

template <typename T>
class FluxOuterLoop {
 public:
  FluxOuterLoop(Real flux_decay, const FluxOuterLoopGains& gains) noexcept
      : e_(T(flux_decay)), kp_(T(gains.kp)), ki_(T(gains.ki)) {}

  /// v2 for the next step from the squared stator-flux reference and measurement (Wb^2).
  T step(T flux2_ref_Wb2, T flux2_Wb2) noexcept {
    using std::sqrt;
    const T error = flux2_ref_Wb2 - flux2_Wb2;
    const T v2_linear = (T(1) - e_) * flux2_ref_Wb2 + kp_ * error + integral_;
    const T flux2 = flux2_Wb2 > T(0) ? flux2_Wb2 : T(0);
    const T floor = e_ * e_ * flux2;
    const T intended = e_ * flux2 + v2_linear;  // F(k+1) of the linear design
    // At the floor the flux shrinks as fast as it can: integrating a negative error there
    // only winds the integrator down, and the flux stays at the floor long after the
    // reference is above it again (anti-windup).
    if (intended > floor || error > T(0)) integral_ += ki_ * error;
    return sqrt(flux2) * sqrt(intended > floor ? intended : floor) - e_ * flux2;
  }
  void reset() noexcept { integral_ = T(0); }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const FluxOuterLoop& old) noexcept { integral_ = old.integral_; }

 private:
  T e_, kp_, ki_;
  T integral_ = T(0);
};

}  // namespace imd::control
