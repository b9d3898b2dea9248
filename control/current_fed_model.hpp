#pragma once
/// Exact discrete model of the current-fed induction motor with stator flux, paper 001,
/// equations (14), (15), (17) and (18). The stator current is held constant over each period
/// in the rotor-aligned (AB) frame; the stator flux is the sample taken just after the current
/// steps to its new value i_{k+1}:
///
///   phi_{k+1} = e^{-eta T0} phi_k + ls (1 - sigma - e^{-eta T0}) i_k + ls sigma i_{k+1}  (15)
///   tau(t)    = tau_k e^{-eta (t - t_k)},  tau_k = k_T n_p i_k^T J phi_k             (14)
///   w_{k+1}   = e^{-c T0/J} w_k + (e^{-c T0/J} - e^{-eta T0}) / (J eta - c) tau_k
///               - (1 - e^{-c T0/J}) / c tau_L,k                                     (17, 18)
///
/// k_T = 3/2 carries the project's amplitude-invariant Clarke convention (the paper has 1).
#include "control/frames.hpp"
#include "control/motor_parameters.hpp"
#include "control/real.hpp"

namespace imd::control {

/// Constant coefficients of the exact discrete model for one motor and period T0.
struct CurrentFedCoefficients {
  Real T0_s = 0.0;                   ///< control period
  Real flux_decay = 0.0;             ///< e^{-eta T0}
  Real flux_from_i_now_H = 0.0;      ///< ls (1 - sigma - e^{-eta T0}), multiplies i_k
  Real flux_from_i_next_H = 0.0;     ///< ls sigma, multiplies i_{k+1}
  Real torque_per_flux_A = 0.0;      ///< k_T n_p: tau = k_T n_p i^T J phi, N m per Wb A
  Real eta_per_s = 0.0;              ///< decay rate of the torque inside a period
  Real speed_decay = 1.0;            ///< e^{-c T0 / J}
  Real speed_decay_minus_one = 0.0;  ///< e^{-c T0 / J} - 1 without cancellation (expm1)
  Real torque_to_speed = 0.0;        ///< (e^{-c T0/J} - e^{-eta T0}) / (J eta - c), rad/s per N m
  Real load_to_speed = 0.0;          ///< -(1 - e^{-c T0/J}) / c (-T0/J at c = 0), rad/s per N m
};

/// Computes the coefficients in closed form, stable for c -> 0 and for J eta -> c. Requires
/// valid parameters and T0_s > 0. Not for tick context.
CurrentFedCoefficients discretize_current_fed(const MotorParameters& motor, Real T0_s);

/// The same in the control arithmetic T: double is the reference above, float the MCU's
/// (control/float_discretization.cpp). In float each coefficient is within 12 u (u = 2^-24)
/// of the value for the float-rounded parameters, times the conditioning of its last
/// difference: (sigma + |expm1(-eta T0)|) / |sigma + expm1(-eta T0)| for flux_from_i_now_H
/// (near 1 at the drive's periods), (eta + c/J) / (eta - c/J) for torque_to_speed; expf and
/// expm1f are taken within 1 ulp. Not for tick context.
template <typename T>
CurrentFedCoefficients discretize_current_fed(const MotorParameters& motor, Real T0_s);
template <>
inline CurrentFedCoefficients discretize_current_fed<double>(const MotorParameters& motor,
                                                             Real T0_s) {
  return discretize_current_fed(motor, T0_s);
}
template <>
CurrentFedCoefficients discretize_current_fed<float>(const MotorParameters& motor, Real T0_s);

/// (exp(x) - 1) / x, equal to 1 at x = 0, without cancellation for small |x|.
double phi1(double x) noexcept;
float phi1(float x) noexcept;

/// One-step maps of the exact discrete model, in float or double. Tick context.
template <typename T>
class CurrentFedModel {
 public:
  explicit CurrentFedModel(const CurrentFedCoefficients& c) noexcept
      : flux_decay_(T(c.flux_decay)),
        flux_from_i_now_H_(T(c.flux_from_i_now_H)),
        flux_from_i_next_H_(T(c.flux_from_i_next_H)),
        torque_per_flux_A_(T(c.torque_per_flux_A)),
        speed_decay_minus_one_(T(c.speed_decay_minus_one)),
        torque_to_speed_(T(c.torque_to_speed)),
        load_to_speed_(T(c.load_to_speed)) {}

  /// Stator flux at t_{k+1} after the current steps to i_{k+1}, equation (15).
  Vec2<T> next_stator_flux(const Vec2<T>& flux_s_AB_Wb, const Vec2<T>& i_s_AB_A,
                           const Vec2<T>& i_s_AB_next_A) const noexcept {
    return flux_decay_ * flux_s_AB_Wb + flux_from_i_now_H_ * i_s_AB_A +
           flux_from_i_next_H_ * i_s_AB_next_A;
  }

  /// Electromagnetic torque at t_k, equation (14).
  T torque_Nm(const Vec2<T>& flux_s_AB_Wb, const Vec2<T>& i_s_AB_A) const noexcept {
    return torque_per_flux_A_ * dot_J(i_s_AB_A, flux_s_AB_Wb);
  }

  /// Speed at t_{k+1} from the speed and torque at t_k and the held load, (17) with (18),
  /// evaluated as an increment so that float keeps the friction term.
  T next_speed(T omega_mech_rad_s, T torque_Nm, T load_Nm) const noexcept {
    return omega_mech_rad_s + (speed_decay_minus_one_ * omega_mech_rad_s +
                               torque_to_speed_ * torque_Nm + load_to_speed_ * load_Nm);
  }

 private:
  T flux_decay_, flux_from_i_now_H_, flux_from_i_next_H_, torque_per_flux_A_;
  T speed_decay_minus_one_, torque_to_speed_, load_to_speed_;
};

}  // namespace imd::control
