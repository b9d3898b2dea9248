#pragma once
// The yardstick of the simulator's speed: a plain indirect field-oriented drive on the ideal
// motor, integrated by RK4 at 10 us, with nothing else (no board, sensors, noise, observer,
// protections, supervisor or telemetry). What drive_sim costs per simulated second against it,
// in the same run, is a figure that does not depend on the machine the way seconds do
// (docs/performance.md, "The simulator").
//
// The design is the textbook one, from the motor's parameters only:
// * current loops (rotor-flux frame, PI with the back-EMF fed forward) at a bandwidth of
//   wc = 2 pi 500 Hz: Kp = sigma wc, Ki = R_eq wc with R_eq = Rs + Rr (Lm/Lr)^2;
// * speed loop at ws = 2 pi 10 Hz: Kp = J ws / Kt, Ki = Kp ws / 5, Kt = 3/2 p (Lm/Lr) psi*;
// * the flux angle from the slip, w_slip = (Rr/Lr) Lm iq* / psi*; id* = psi* / Lm.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "control/motor_parameters.hpp"

namespace imd::bench {

struct ReferenceIfocCase {
  control::MotorParameters motor;
  double flux_Wb = 0.0;        ///< psi*
  double v_max_V = 0.0;        ///< the voltage vector's limit
  double i_max_A = 0.0;        ///< the current command's limit
  double duration_s = 0.0;
  double sample_period_s = 1e-4;
  int substeps = 10;  ///< RK4 steps per period (10 us at 10 kHz)
};

struct ReferenceIfocResult {
  long ticks = 0;
  double speed_error_rms_rad_s = 0.0;  ///< over the second half
};

/// `speed_at(t)`: the speed reference (rad/s) at time t; `load_at(t)`: the load torque (N m).
template <typename SpeedAt, typename LoadAt>
ReferenceIfocResult run_reference_ifoc(const ReferenceIfocCase& c, const SpeedAt& speed_at,
                                       const LoadAt& load_at) {
  using State = Eigen::Matrix<double, 5, 1>;  // rotor flux (alpha, beta), current, speed
  const control::MotorParameters& m = c.motor;
  const double sigma = m.Ls_H - m.Lm_H * m.Lm_H / m.Lr_H;
  const double alpha = m.Rr_Ohm / m.Lr_H, beta = m.Lm_H / (sigma * m.Lr_H);
  const double gamma = m.Rs_Ohm / sigma + alpha * m.Lm_H * beta;
  const double k_torque = 1.5 * m.pole_pairs * m.Lm_H / m.Lr_H;
  const double pi = 3.14159265358979323846;
  const double wc = 2 * pi * 500.0, ws = 2 * pi * 10.0;
  const double kp_i = sigma * wc, ki_i = (m.Rs_Ohm + m.Rr_Ohm * std::pow(m.Lm_H / m.Lr_H, 2)) * wc;
  const double kp_w = m.J_kgm2 * ws / (k_torque * c.flux_Wb), ki_w = kp_w * ws / 5;
  const double T = c.sample_period_s, h = T / c.substeps;
  const double id_ref = c.flux_Wb / m.Lm_H;
  const double iq_max = std::sqrt(std::max(0.0, c.i_max_A * c.i_max_A - id_ref * id_ref));

  State x = State::Zero();
  double theta_e = 0, int_w = 0, int_d = 0, int_q = 0, error2 = 0;
  ReferenceIfocResult r;
  const long ticks = std::lround(c.duration_s / T);
  for (long k = 0; k < ticks; ++k) {
    const double t = double(k) * T;
    const double w_ref = speed_at(t), load = load_at(t);
    // Speed PI, its integrator held while the command is limited.
    const double e_w = w_ref - x(4);
    const double iq_free = kp_w * e_w + ki_w * (int_w + e_w * T);
    const double iq_ref = std::clamp(iq_free, -iq_max, iq_max);
    if (iq_ref == iq_free) int_w += e_w * T;
    // Currents in the flux frame; the flux angle from the slip.
    const double w_slip = alpha * m.Lm_H * iq_ref / c.flux_Wb;
    const double w_e = m.pole_pairs * x(4) + w_slip;
    const double cs = std::cos(theta_e), sn = std::sin(theta_e);
    const double id = cs * x(2) + sn * x(3), iq = -sn * x(2) + cs * x(3);
    const double e_d = id_ref - id, e_q = iq_ref - iq;
    double vd = kp_i * e_d + ki_i * (int_d + e_d * T) - w_e * sigma * iq;
    double vq = kp_i * e_q + ki_i * (int_q + e_q * T) + w_e * (sigma * id + m.Lm_H / m.Lr_H *
                                                                              c.flux_Wb);
    const double v = std::hypot(vd, vq);
    if (v > c.v_max_V) {
      vd *= c.v_max_V / v;
      vq *= c.v_max_V / v;
    } else {
      int_d += e_d * T;
      int_q += e_q * T;
    }
    const double ua = cs * vd - sn * vq, ub = sn * vd + cs * vq;
    // The motor over the period, the voltage held (model (1) of paper 000).
    const auto f = [&](const State& s) {
      const double pw = m.pole_pairs * s(4);
      State d;
      d(0) = -alpha * s(0) - pw * s(1) + alpha * m.Lm_H * s(2);
      d(1) = -alpha * s(1) + pw * s(0) + alpha * m.Lm_H * s(3);
      d(2) = alpha * beta * s(0) + pw * beta * s(1) - gamma * s(2) + ua / sigma;
      d(3) = alpha * beta * s(1) - pw * beta * s(0) - gamma * s(3) + ub / sigma;
      const double torque = k_torque * (s(0) * s(3) - s(1) * s(2));
      d(4) = (torque - load - m.friction_Nms * s(4)) / m.J_kgm2;
      return d;
    };
    for (int i = 0; i < c.substeps; ++i) {
      const State k1 = f(x), k2 = f(x + h / 2 * k1), k3 = f(x + h / 2 * k2), k4 = f(x + h * k3);
      x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    theta_e = std::remainder(theta_e + w_e * T, 2 * pi);
    if (2 * k >= ticks) error2 += e_w * e_w;
    ++r.ticks;
  }
  r.speed_error_rms_rad_s = std::sqrt(error2 / double(ticks - ticks / 2));
  return r;
}

}  // namespace imd::bench
