#pragma once
/// Exact sampled model of the voltage-fed induction motor under the preliminary feedback (2)
/// of paper 000, Section II. In the rotor-aligned frame the electrical states obey a linear
/// time-invariant system, so with the input held over the period the model is exact:
///
///   [Phi; I]_{k+1} = A_d [Phi; I]_k + B_d v_k
///   w_{k+1} = w_k + eta1 I_k^T J Phi_k + (eta2 Phi_k^T + eta3 I_k^T) J v_k - C_L delta / J
///   th_{k+1} = th_k + w_k delta + kappa1 I_k^T J Phi_k + (kappa2 Phi_k^T + kappa3 I_k^T) J v_k
///              - C_L delta^2 / (2 J)
///
/// generalised to viscous friction c (w_k and C_L then enter through exponential weights; with
/// c = 0 the paper's equations result). The derivation is in docs/derivations.md.
#include "control/frames.hpp"
#include "control/motor_parameters.hpp"
#include "control/real.hpp"

namespace imd::control {

/// The constant coefficients of the exact sampled model for one motor and sample period.
struct VoltageFedCoefficients {
  Real delta_s = 0.0;  ///< sample period
  // A_d = [a11 I, a12 I; a21 I, a22 I] and B_d = [b1 I; b2 I].
  Real a11 = 0.0, a12 = 0.0, a21 = 0.0, a22 = 0.0;
  Real b1 = 0.0, b2 = 0.0;
  // Speed and position increments per unit of the skew products (units rad/s or rad per A Wb,
  // per Wb V and per A V).
  Real eta1 = 0.0, eta2 = 0.0, eta3 = 0.0;
  Real kappa1 = 0.0, kappa2 = 0.0, kappa3 = 0.0;
  // Mechanical coefficients: exp(-c delta/J) and its integrals; 1, delta, -delta/J and
  // -delta^2/(2J) without friction.
  Real omega_decay = 1.0;            ///< coefficient of w_k in w_{k+1}
  Real omega_decay_minus_one = 0.0;  ///< omega_decay - 1 without cancellation (expm1)
  Real omega_to_theta_s = 0.0;       ///< coefficient of w_k in th_{k+1}
  Real load_to_omega = 0.0;          ///< coefficient of C_L in w_{k+1}, rad/s per N m
  Real load_to_theta = 0.0;          ///< coefficient of C_L in th_{k+1}, rad per N m
};

/// Computes the coefficients numerically exactly from structured matrix exponentials
/// (control/block_exponential.hpp: a few hundred multiply-adds, no allocation). Not for tick
/// context: start-up and the service loop. Requires valid parameters and delta_s > 0.
VoltageFedCoefficients discretize_voltage_fed(const MotorParameters& motor, Real delta_s);

/// The same coefficients computed in the control arithmetic T: T = double is the reference
/// above; T = float is the MCU's, cheap enough to recompute outside the tick for a new rotor
/// resistance (control/float_discretization.cpp), with the Metzler exponential of
/// control/metzler_exponential.hpp. Its error, relative to each coefficient, is at most
///   2^s 80 u + (2 theta_0 + 4) eta_in + 8 u,   u = 2^-24,
/// 2^s 80 u the exponential's rounding (s its squarings, theta_0 its shifted generator's norm:
/// metzler_squarings, metzler_shifted_norm); (2 theta_0 + 4) eta_in the generator's own
/// rounding, eta_in relative on each entry: a Metzler exponential is monotone in its
/// generator, so the entries move by at most eta_in (mu + mean walk length) <= eta_in (theta_0 +
/// theta_0 + 4); 8 u the final products and the mechanical expm1f. eta_in = 9 u when float
/// represents the parameters exactly (sigma Lr by a fused difference within 2 u, then at most
/// seven operations, (alpha + gamma) delta the longest chain); parameters that float rounds add
/// 3 u and twice sigma's conditioning Ls Lr / (Ls Lr - Lm^2) (tens for real motors) in u.
/// docs/derivations.md derives it. Not for tick context.
template <typename T>
VoltageFedCoefficients discretize_voltage_fed(const MotorParameters& motor, Real delta_s);
template <>
inline VoltageFedCoefficients discretize_voltage_fed<double>(const MotorParameters& motor,
                                                             Real delta_s) {
  return discretize_voltage_fed(motor, delta_s);
}
template <>
VoltageFedCoefficients discretize_voltage_fed<float>(const MotorParameters& motor, Real delta_s);

/// The generators the float discretization exponentiates, already times delta: the axis
/// generator A3 delta, its additive compound times delta and the friction g = -f delta / J.
struct VoltageFedFloatGenerators {
  Eigen::Matrix3f axis = Eigen::Matrix3f::Zero();
  Eigen::Matrix3f compound = Eigen::Matrix3f::Zero();
  float friction = 0.0f;
  float mu_1_per_kgm2 = 0.0f;     ///< mu = 3/2 p Lm / (J Lr) of paper 000, 1/(kg m^2)
  float inv_J_1_per_kgm2 = 0.0f;  ///< 1 / J, 1/(kg m^2)
  float delta_s = 0.0f;         ///< sample period
};
VoltageFedFloatGenerators voltage_fed_float_generators(const MotorParameters& motor,
                                                       Real delta_s) noexcept;

/// Generator of one axis of the rotor-frame dynamics (5) with the held input as a third state:
/// d/dt (phi, i, v) = A3 (phi, i, v); A = A3 (x) I2 acts on both axes alike.
Eigen::Matrix3d voltage_fed_axis_generator(const MotorParameters& motor);

/// Additive second compound A^[2] of a 3x3 matrix, index pairs ordered (0,1), (0,2), (1,2).
/// The 2x2 minors of exp(A t) are the entries of exp(A^[2] t).
Eigen::Matrix3d additive_compound(const Eigen::Matrix3d& a);

/// State in the rotor-aligned frame: (Phi~, I~, w, th) of paper 000.
template <typename T>
struct RotorFrameState {
  Vec2<T> flux_r_AB_Wb = Vec2<T>::Zero();  ///< rotor flux
  Vec2<T> i_s_AB_A = Vec2<T>::Zero();      ///< stator current
  T omega_mech_rad_s = T(0);               ///< mechanical rotor speed
  T theta_mech_rad = T(0);                 ///< mechanical rotor position
};

/// Changes of speed and position over one period.
template <typename T>
struct MechanicalIncrement {
  T omega_mech_rad_s = T(0);  ///< w_{k+1} - w_k
  T theta_mech_rad = T(0);    ///< th_{k+1} - th_k
};

/// One-step predictor of the exact sampled model, in float or double. The mechanical rows are
/// evaluated as increments: the small terms (eta3 ~ 1e-9, kappa3 ~ 1e-13 for the paper motor)
/// are not lost against w_k or th_k, and a caller may keep th wrapped.
template <typename T>
class VoltageFedModel {
 public:
  explicit VoltageFedModel(const VoltageFedCoefficients& c) noexcept
      : a11_(T(c.a11)),
        a12_(T(c.a12)),
        a21_(T(c.a21)),
        a22_(T(c.a22)),
        b1_(T(c.b1)),
        b2_(T(c.b2)),
        eta1_(T(c.eta1)),
        eta2_(T(c.eta2)),
        eta3_(T(c.eta3)),
        kappa1_(T(c.kappa1)),
        kappa2_(T(c.kappa2)),
        kappa3_(T(c.kappa3)),
        omega_decay_minus_one_(T(c.omega_decay_minus_one)),
        omega_to_theta_s_(T(c.omega_to_theta_s)),
        load_to_omega_(T(c.load_to_omega)),
        load_to_theta_(T(c.load_to_theta)) {}

  /// State at step k+1 from the state at step k, the rotor-frame input v~_k (the voltage v of
  /// (2) rotated by -p th_k) and the load C_L,k held over the period. Tick context.
  RotorFrameState<T> predict(const RotorFrameState<T>& x, const Vec2<T>& v_AB_V,
                             T load_Nm) const noexcept {
    RotorFrameState<T> next;
    next.flux_r_AB_Wb = a11_ * x.flux_r_AB_Wb + a12_ * x.i_s_AB_A + b1_ * v_AB_V;
    next.i_s_AB_A = a21_ * x.flux_r_AB_Wb + a22_ * x.i_s_AB_A + b2_ * v_AB_V;
    const MechanicalIncrement<T> step = increment(x, v_AB_V, load_Nm);
    next.omega_mech_rad_s = x.omega_mech_rad_s + step.omega_mech_rad_s;
    next.theta_mech_rad = x.theta_mech_rad + step.theta_mech_rad;
    return next;
  }

  /// Speed and position increments over the period. Tick context.
  MechanicalIncrement<T> increment(const RotorFrameState<T>& x, const Vec2<T>& v_AB_V,
                                   T load_Nm) const noexcept {
    const T torque_product = dot_J(x.i_s_AB_A, x.flux_r_AB_Wb);  // I^T J Phi
    const T flux_input_product = dot_J(x.flux_r_AB_Wb, v_AB_V);  // Phi^T J v
    const T current_input_product = dot_J(x.i_s_AB_A, v_AB_V);   // I^T J v
    MechanicalIncrement<T> step;
    step.omega_mech_rad_s = omega_decay_minus_one_ * x.omega_mech_rad_s + eta1_ * torque_product +
                            eta2_ * flux_input_product + eta3_ * current_input_product +
                            load_to_omega_ * load_Nm;
    step.theta_mech_rad = omega_to_theta_s_ * x.omega_mech_rad_s + kappa1_ * torque_product +
                          kappa2_ * flux_input_product + kappa3_ * current_input_product +
                          load_to_theta_ * load_Nm;
    return step;
  }

 private:
  T a11_, a12_, a21_, a22_, b1_, b2_;
  T eta1_, eta2_, eta3_, kappa1_, kappa2_, kappa3_;
  T omega_decay_minus_one_, omega_to_theta_s_, load_to_omega_, load_to_theta_;
};

}  // namespace imd::control
