#pragma once
/// The largest rotor flux the voltage allows in steady state (field weakening). In the
/// rotor-flux frame at flux frequency w_e, with psi_r = Lm i_d in steady state:
///   u_d = Rs i_d - w_e sigma i_q,   u_q = Rs i_q + w_e Ls i_d,
/// and |u| <= V gives the quadratic A i_d^2 + B i_d + C <= 0 with A = Rs^2 + w_e^2 Ls^2,
/// B = 2 Rs w_e i_q (Ls - sigma), C = (Rs^2 + w_e^2 sigma^2) i_q^2 - V^2. Its larger root is the
/// flux current at the limit. At high speed it tends to V / (w_e Ls): the flux falls as 1/w once
/// the voltage runs out, and less early for a light load (small i_q) than for a heavy one.
///
/// The limit falls with the load. It must not fall below the flux of the most torque the voltage
/// allows (maximum torque per volt): with Rs neglected, u_d = -w_e sigma i_q and
/// u_q = w_e Ls i_d, and the torque ~ i_d i_q on the ellipse (sigma i_q)^2 + (Ls i_d)^2 =
/// (V / w_e)^2 is largest at Ls i_d = V / (sqrt 2 w_e): psi = Lm V / (sqrt 2 w_e Ls). Less flux
/// would ask for still more torque current and lower the limit again, down to no flux at all.
/// Tick context.
#include <cmath>
#include <limits>

#include "control/real.hpp"

namespace imd::control {

/// Share of the voltage disk the steady state may use above base speed, the same for every
/// law; the rest is left to the transients of the current (or flux) control.
inline constexpr Real kFieldWeakeningVoltageShare = Real(0.9);

template <typename T>
struct FieldWeakeningMotor {
  T Rs_Ohm, Ls_H, sigma_H, Lm_H;
};

/// The largest steady-state rotor flux at flux frequency w_e (electrical rad/s) and torque
/// current i_q within a stator-voltage modulus V; +inf without a limit, 0 when the torque
/// current alone needs more than V.
template <typename T>
T voltage_limited_flux_Wb(const FieldWeakeningMotor<T>& m, T omega_e_rad_s, T i_q_A,
                          T v_max_V) noexcept {
  if (!(v_max_V < std::numeric_limits<T>::infinity())) return std::numeric_limits<T>::infinity();
  const T w = omega_e_rad_s;
  const T a = m.Rs_Ohm * m.Rs_Ohm + w * w * m.Ls_H * m.Ls_H;
  const T b = T(2) * m.Rs_Ohm * w * i_q_A * (m.Ls_H - m.sigma_H);
  const T c = (m.Rs_Ohm * m.Rs_Ohm + w * w * m.sigma_H * m.sigma_H) * i_q_A * i_q_A -
              v_max_V * v_max_V;
  const T discriminant = b * b - T(4) * a * c;
  if (!(discriminant >= T(0)) || !(a > T(0))) return T(0);
  const T i_d = (-b + std::sqrt(discriminant)) / (T(2) * a);
  return i_d > T(0) ? m.Lm_H * i_d : T(0);
}

/// The flux of the most torque within a stator-voltage modulus V at flux frequency w_e (Rs
/// neglected); +inf without a limit or at standstill.
template <typename T>
T max_torque_per_volt_flux_Wb(const FieldWeakeningMotor<T>& m, T omega_e_rad_s,
                              T v_max_V) noexcept {
  const T w = std::abs(omega_e_rad_s);
  if (!(v_max_V < std::numeric_limits<T>::infinity()) || !(w > T(0))) {
    return std::numeric_limits<T>::infinity();
  }
  return m.Lm_H * v_max_V / (T(1.4142135623730951) * w * m.Ls_H);
}

}  // namespace imd::control
