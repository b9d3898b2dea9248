#pragma once
/// Position, speed and load observer driven by the quantized encoder angle, built on the exact
/// mechanical rows of the sampled model (paper 000, Section II, with the kappa terms):
///   th_{k+1} = th + T_w w + kappa1 q + (kappa2 Phi + kappa3 I)^T J v + T_L C_L
///   w_{k+1}  = d_w w + eta1 q + (eta2 Phi + eta3 I)^T J v + g_L C_L,     C_L constant,
/// with q = I~^T J Phi~. The electrical terms come from the flux estimate, the measured current
/// and the applied input. In filter form (predict at the end of a tick, correct at the start of
/// the next)
///   x^-_k = A x_{k-1} + (electrical terms),   x_k = x^-_k + L wrap(th_meas,k - th^-_k),
/// the error obeys e_k = (A - L C A) e_{k-1}, C = [1 0 0]; L places its three poles at
/// exp(-bandwidth delta) (in closed form, below). The angle is kept in [0, 2 pi) so that float
/// keeps its resolution. Tick context except the constructor.
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <numbers>
#include <type_traits>

#include "control/frames.hpp"
#include "control/real.hpp"
#include "control/voltage_fed_model.hpp"

namespace imd::control {

struct EncoderObserverConfig {
  Real bandwidth_rad_s = 400.0;  ///< the three error poles sit at exp(-bandwidth delta)
};

/// Observer gain L for the mechanical model of `c`: the three poles of A - L C A at
/// p = exp(-bandwidth delta). A = [1 t l; 0 1+e g; 0 0 1] (t = omega_to_theta, l =
/// load_to_theta, e = omega_decay - 1, g = load_to_omega); matching det(zI - A + L C A) to
/// (z - p)^3 is linear in L, and its solution, with s = 1 - p and D = g t - e l, is
///   L1 = (e + 3s - 3s^2 + s^3) / (1 + e)
///   L2 = (g t (e^2 + 3 e s + 3 s^2 - s^3) - l (e + s)^3) / (t (1 + e) D)
///   L3 = s^3 / D
/// (docs/derivations.md, "The encoder observer's gain"). In closed form rather than by
/// Ackermann's formula: the observability matrix [CA; CA^2; CA^3] has rows that differ in
/// their O(delta) terms (condition 1e6 to 7e8 on the test motors), so its inverse loses six to
/// nine digits, all of float's. These expressions lose only what their few roundings and one
/// source of cancellation cost. With x = (c/J) / bandwidth, the mechanical pole over the
/// observer's: D = g t - e l has none (both terms share a sign: e <= 0, g and l < 0, t > 0);
/// L1's numerator loses a factor (3 + x) / (3 - x) (1.07 at x = 0.1; at x = 3 it vanishes, and
/// the gain with it); L2's at most (x^2 + 3x + 3) / (x^2 - 3x + 3) (1.22 at x = 0.1, never above
/// 14). A drive's mechanical pole is far below its observer's bandwidth (x below 2e-3 on the
/// test motors down to 50 rad/s, 0.1 in the test's friction cases).
template <typename T = double>
Eigen::Matrix<T, 3, 1> place_encoder_observer(const VoltageFedCoefficients& c,
                                              T bandwidth_rad_s) noexcept {
  static_assert(std::is_floating_point_v<T>, "place_encoder_observer<float or double>");
  const T t = T(c.omega_to_theta_s), l = T(c.load_to_theta);
  const T e = T(c.omega_decay_minus_one), g = T(c.load_to_omega);
  const T s = -std::expm1(-bandwidth_rad_s * T(c.delta_s));  // 1 - p without cancellation
  const T s2 = s * s, s3 = s2 * s, es = e + s;
  const T d = g * t - e * l;
  const T one_plus_e = T(1) + e;
  return {
      (e + T(3) * s - T(3) * s2 + s3) / one_plus_e,
      (g * t * (e * e + T(3) * e * s + T(3) * s2 - s3) - l * es * es * es) / (t * one_plus_e * d),
      s3 / d};
}

/// The error matrix A - L C A of the observer, for checks.
template <typename T = double>
Eigen::Matrix<T, 3, 3> encoder_observer_error_matrix(const VoltageFedCoefficients& c,
                                                     const Eigen::Matrix<T, 3, 1>& gain) noexcept {
  Eigen::Matrix<T, 3, 3> a;
  a << T(1), T(c.omega_to_theta_s), T(c.load_to_theta),  //
      T(0), T(c.omega_decay), T(c.load_to_omega),        //
      T(0), T(0), T(1);
  return a - gain * a.row(0);  // C A is A's first row
}

/// fmod(x, 2 pi), out of line: wrap_pi's path for angles beyond two turns, which the tick never
/// takes, kept out of the tick's inlined code.
template <typename T>
[[gnu::noinline, gnu::cold]] T fmod_two_pi(T x) noexcept {
  return std::fmod(x, T(2 * std::numbers::pi));
}

/// Wraps an angle into [-pi, pi). Inlined: the tick wraps four angles, and a call costs about
/// a third of the wrap itself on the MCU.
template <typename T>
[[gnu::always_inline]] inline T wrap_pi(T angle_rad) noexcept {
  const T two_pi = T(2 * std::numbers::pi);
  T shifted = angle_rad + T(std::numbers::pi);
  // Within two turns fmod is one exact subtraction (Sterbenz: two_pi <= x < 2 two_pi) or none;
  // the tick's angles always are, and the MCU's fmodf costs as much as the rest of wrap_pi
  // several times over. Farther out, fmod itself.
  if (shifted >= two_pi && shifted < T(2) * two_pi) {
    shifted -= two_pi;
  } else if (!(shifted > -two_pi && shifted < two_pi)) {
    shifted = fmod_two_pi(shifted);
  }
  return (shifted < T(0) ? shifted + two_pi : shifted) - T(std::numbers::pi);
}

/// The largest speed and load-estimate errors that the angle's quantization can cause: the
/// measured angle is off by at most one step q, and the errors answer it through the impulse
/// response (A - L C A)^j L, so they are bounded by q times its l1 norm. Construction only.
struct QuantizationErrorBounds {
  Real omega_rad_s = 0.0;
  Real load_Nm = 0.0;
};
/// Computed in T: on the MCU in float, where a few thousand 3x3 steps cost tens of thousands of
/// instructions rather than millions in soft double. The results are raised by 3 n epsilon for
/// the n steps' rounding (5.7e-4 at 10 kHz, 1.1e-3 at 20 kHz in float): a margin, not a proven
/// bound, since the rounding also propagates through the powers of a non-normal matrix; it is
/// about 300 times what the float sums differ from the double ones on the test motors
/// (tests/control/test_encoder_observer_gain.cpp checks they never come out below).
template <typename T = double>
QuantizationErrorBounds encoder_quantization_bounds(const VoltageFedCoefficients& c,
                                                    T bandwidth_rad_s, T q_rad) noexcept {
  static_assert(std::is_floating_point_v<T>, "encoder_quantization_bounds<float or double>");
  Eigen::Matrix<T, 3, 1> response = place_encoder_observer<T>(c, bandwidth_rad_s);
  const Eigen::Matrix<T, 3, 3> error = encoder_observer_error_matrix<T>(c, response);
  T omega = T(0), load = T(0);
  // The triple pole z = e^{-bandwidth delta} decays as k^2 z^k: 60 time constants leave 1e-20.
  const int terms = static_cast<int>(T(60) / (bandwidth_rad_s * T(c.delta_s))) + 100;
  for (int j = 0; j < terms; ++j) {
    omega += std::abs(response(1));
    load += std::abs(response(2));
    response = error * response;
  }
  const T rounding = T(1) + T(3 * terms) * std::numeric_limits<T>::epsilon();
  return {Real(omega * q_rad * rounding), Real(load * q_rad * rounding)};
}

template <typename T>
class EncoderObserver {
 public:
  EncoderObserver(const VoltageFedCoefficients& c, const EncoderObserverConfig& config)
      : omega_to_theta_(T(c.omega_to_theta_s)),
        load_to_theta_(T(c.load_to_theta)),
        omega_decay_minus_one_(T(c.omega_decay_minus_one)),
        load_to_omega_(T(c.load_to_omega)),
        eta1_(T(c.eta1)),
        eta2_(T(c.eta2)),
        eta3_(T(c.eta3)),
        kappa1_(T(c.kappa1)),
        kappa2_(T(c.kappa2)),
        kappa3_(T(c.kappa3)) {
    const Eigen::Matrix<T, 3, 1> l = place_encoder_observer<T>(c, T(config.bandwidth_rad_s));
    gain_theta_ = l(0);
    gain_omega_ = l(1);
    gain_load_ = l(2);
  }

  T theta_mech_rad() const noexcept { return theta_; }  ///< in [0, 2 pi)
  T omega_mech_rad_s() const noexcept { return omega_; }
  T load_Nm() const noexcept { return load_; }

  void reset(T theta_mech_rad, T omega_mech_rad_s = T(0), T load_Nm = T(0)) noexcept {
    theta_ = wrap_2pi(theta_mech_rad);
    omega_ = omega_mech_rad_s;
    load_ = load_Nm;
  }

  /// Predicts step k+1 from step k, with I~_k, the flux estimate and the v~_k that acts over
  /// the period. Tick context (end of tick k).
  void predict(const Vec2<T>& i_s_AB_A, const Vec2<T>& flux_r_AB_Wb,
               const Vec2<T>& v_AB_V) noexcept {
    const T q = dot_J(i_s_AB_A, flux_r_AB_Wb);
    const T flux_input = dot_J(flux_r_AB_Wb, v_AB_V);
    const T current_input = dot_J(i_s_AB_A, v_AB_V);
    const T theta_step = omega_to_theta_ * omega_ + kappa1_ * q + kappa2_ * flux_input +
                         kappa3_ * current_input + load_to_theta_ * load_;
    const T omega_step = omega_decay_minus_one_ * omega_ + eta1_ * q + eta2_ * flux_input +
                         eta3_ * current_input + load_to_omega_ * load_;
    theta_ = wrap_2pi(theta_ + theta_step);
    omega_ = omega_ + omega_step;
  }

  /// Corrects the prediction with the measured angle of the new step. Tick context (start of
  /// tick k+1).
  void correct(T theta_measured_rad) noexcept {
    const T innovation = wrap_pi(theta_measured_rad - theta_);
    theta_ = wrap_2pi(theta_ + gain_theta_ * innovation);
    omega_ = omega_ + gain_omega_ * innovation;
    load_ = load_ + gain_load_ * innovation;
  }

  /// predict() then correct().
  void update(const Vec2<T>& i_s_AB_A, const Vec2<T>& flux_r_AB_Wb, const Vec2<T>& v_AB_V,
              T theta_measured_rad) noexcept {
    predict(i_s_AB_A, flux_r_AB_Wb, v_AB_V);
    correct(theta_measured_rad);
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const EncoderObserver& old) noexcept {
    theta_ = old.theta_;
    omega_ = old.omega_;
    load_ = old.load_;
  }

 private:
  static T wrap_2pi(T angle_rad) noexcept {
    return wrap_pi(angle_rad - T(std::numbers::pi)) + T(std::numbers::pi);
  }

  T omega_to_theta_, load_to_theta_, omega_decay_minus_one_, load_to_omega_;
  T eta1_, eta2_, eta3_, kappa1_, kappa2_, kappa3_;
  T gain_theta_ = T(0), gain_omega_ = T(0), gain_load_ = T(0);
  T theta_ = T(0), omega_ = T(0), load_ = T(0);
};

}  // namespace imd::control
