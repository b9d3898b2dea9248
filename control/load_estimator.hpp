#pragma once
/// Speed and load-torque estimator of paper 000, Section IV, for a measured speed:
///   w^_{k+1} = w_k (decayed) + eta1 I~^T J Phi^ + (eta2 Phi^ + eta3 I~)^T J v~ + g C^_L + l1 e
///   C^_{L,k+1} = C^_L + l2 e,     e = w_k - w^_k,   g = load_to_omega (-delta/J without friction)
/// With exact flux the errors obey (13): [e_w; e_L]_{k+1} = [[-l1, g], [-l2, 1]] [e_w; e_L]_k.
/// The gains are placed so that this matrix has the requested poles (Schur-stable); see
/// docs/control.md for the paper's printed gains, which are not. Tick context except the
/// constructor.
#include <Eigen/Core>
#include <complex>

#include "control/frames.hpp"
#include "control/real.hpp"
#include "control/voltage_fed_model.hpp"

namespace imd::control {

struct LoadEstimatorGains {
  Real l1 = 0.0;
  Real l2 = 0.0;
};

/// Gains that give the error matrix of (13) the poles z1, z2 (real, |z| < 1):
/// trace 1 - l1 = z1 + z2 and determinant -l1 + g l2 = z1 z2.
inline LoadEstimatorGains place_load_estimator(const VoltageFedCoefficients& c, Real z1, Real z2) {
  LoadEstimatorGains gains;
  gains.l1 = 1 - (z1 + z2);
  gains.l2 = (z1 * z2 + gains.l1) / c.load_to_omega;
  return gains;
}

/// The error matrix of (13) for given gains.
inline Eigen::Matrix2d load_estimator_error_matrix(const VoltageFedCoefficients& c,
                                                   const LoadEstimatorGains& gains) {
  Eigen::Matrix2d m;
  m << -gains.l1, c.load_to_omega, -gains.l2, 1.0;
  return m;
}

template <typename T>
class LoadEstimator {
 public:
  LoadEstimator(const VoltageFedCoefficients& c, const LoadEstimatorGains& gains) noexcept
      : eta1_(T(c.eta1)),
        eta2_(T(c.eta2)),
        eta3_(T(c.eta3)),
        omega_decay_(T(c.omega_decay)),
        load_to_omega_(T(c.load_to_omega)),
        l1_(T(gains.l1)),
        l2_(T(gains.l2)) {}

  T load_Nm() const noexcept { return load_; }
  T omega_mech_rad_s() const noexcept { return omega_; }
  void reset(T omega_mech_rad_s, T load_Nm = T(0)) noexcept {
    omega_ = omega_mech_rad_s;
    load_ = load_Nm;
  }

  /// From step k to k+1, with the measured speed w_k, I~_k, the flux estimate and applied v~_k.
  void update(T omega_measured_rad_s, const Vec2<T>& i_s_AB_A, const Vec2<T>& flux_r_AB_Wb,
              const Vec2<T>& v_AB_V) noexcept {
    const T error = omega_measured_rad_s - omega_;
    const Vec2<T> g = eta2_ * flux_r_AB_Wb + eta3_ * i_s_AB_A;
    omega_ = omega_decay_ * omega_measured_rad_s + eta1_ * dot_J(i_s_AB_A, flux_r_AB_Wb) +
             dot_J(g, v_AB_V) + load_to_omega_ * load_ + l1_ * error;
    load_ = load_ + l2_ * error;
  }

 private:
  T eta1_, eta2_, eta3_, omega_decay_, load_to_omega_, l1_, l2_;
  T omega_ = T(0);
  T load_ = T(0);
};

}  // namespace imd::control
