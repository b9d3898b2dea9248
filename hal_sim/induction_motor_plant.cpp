#include "hal_sim/induction_motor_plant.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <numbers>

#include "hal_sim/rk4.hpp"
#include "hal_sim/rk6_integrator.hpp"

namespace imd::sim {
namespace {

using StateVector = InductionMotorPlant::StateVector;

StateVector pack(const PlantState& s) {
  StateVector x;
  x << s.flux_r_alphabeta_Wb, s.i_s_alphabeta_A, s.omega_mech_rad_s, s.theta_mech_rad;
  return x;
}

PlantState unpack(const StateVector& x) {
  return {x.segment<2>(0), x.segment<2>(2), x(4), x(5)};
}

}  // namespace

Vec2 phase_axis(int phase) noexcept {
  constexpr double kHalfSqrt3 = std::numbers::sqrt3 / 2.0;
  switch (phase) {
    case 1:
      return {-0.5, kHalfSqrt3};
    case 2:
      return {-0.5, -kHalfSqrt3};
    default:
      return {1.0, 0.0};
  }
}

InductionMotorPlant::InductionMotorPlant(const control::MotorParameters& motor,
                                         const PlantConfig& config)
    : motor_(motor),
      k_(control::derive_voltage_fed<double>(motor)),
      per_sigma_H_(1.0 / k_.sigma_H),
      per_J_kgm2_(1.0 / double(motor.J_kgm2)),
      config_(config) {
  assert(config.period_s > 0.0 && config.rk4_substeps >= 1);
}

void InductionMotorPlant::set_resistances(double Rs_Ohm, double Rr_Ohm) noexcept {
  assert(Rs_Ohm > 0.0 && Rr_Ohm > 0.0);
  motor_.Rs_Ohm = Real(Rs_Ohm);
  motor_.Rr_Ohm = Real(Rr_Ohm);
  k_ = control::derive_voltage_fed<double>(motor_);
}

void InductionMotorPlant::set_open_phases(unsigned mask) noexcept {
  assert(mask < 8u);
  open_phases_ = mask;
  open_axis_ = Vec2::Zero();
  for (int phase = 0; phase < 3; ++phase) {
    if (mask == 1u << phase) open_axis_ = phase_axis(phase);
  }
  state_.i_s_alphabeta_A = constrained(state_.i_s_alphabeta_A);
}

Vec2 InductionMotorPlant::constrained(const Vec2& current) const noexcept {
  if (open_phases_ == 0) return current;
  if (std::popcount(open_phases_) >= 2) return Vec2::Zero();  // no current path is left
  return current - open_axis_.dot(current) * open_axis_;
}

double InductionMotorPlant::torque_Nm(const PlantState& s) const noexcept {
  return torque_Nm(s.i_s_alphabeta_A, s.flux_r_alphabeta_Wb);
}

double InductionMotorPlant::torque_Nm(const Vec2& i_s_A, const Vec2& flux_r_Wb) const noexcept {
  return k_.mu_per_kgm2 * motor_.J_kgm2 * control::dot_J(i_s_A, flux_r_Wb);
}

Vec2 InductionMotorPlant::flux_s_alphabeta_Wb(const Vec2& i_s_alphabeta_A) const noexcept {
  return k_.sigma_H * i_s_alphabeta_A + motor_.Lm_H / motor_.Lr_H * state_.flux_r_alphabeta_Wb;
}

StateVector InductionMotorPlant::voltage_fed_derivative(const StateVector& x, const Vec2& u,
                                                        double load_Nm) const noexcept {
  const Vec2 flux = x.segment<2>(0);
  const Vec2 current = x.segment<2>(2);
  const double omega = x(4);
  const double p_omega = motor_.pole_pairs * omega;
  const Vec2 j_flux = control::J_times(flux);
  const double torque = torque_Nm(current, flux);
  StateVector dx;
  dx.segment<2>(0) =
      -k_.alpha_per_s * flux + p_omega * j_flux + k_.alpha_per_s * motor_.Lm_H * current;
  dx.segment<2>(2) = k_.alpha_per_s * k_.beta_per_H * flux - p_omega * k_.beta_per_H * j_flux -
                     k_.gamma_per_s * current + u * per_sigma_H_;
  // Floating terminals cancel dI/dt along the open phases' axes.
  if (open_phases_ != 0) dx.segment<2>(2) = constrained(dx.segment<2>(2));
  dx(4) = (torque + shaft_torque_Nm(omega, load_Nm)) * per_J_kgm2_;
  dx(5) = omega;
  return dx;
}

template <bool smooth, typename Rhs>
StateVector InductionMotorPlant::integrate_period(const StateVector& x,
                                                  const Rhs& rhs) const noexcept {
  if (smooth && config_.integrator == PlantIntegrator::rk6 && brake_Nm_ == 0.0) {
    // The speed at the period's start sets the step; within one period it changes by far less
    // than the margin of the bound (plant_integrator.hpp).
    const double rho_per_s =
        k_.alpha_per_s + k_.gamma_per_s + motor_.pole_pairs * std::abs(x(4));
    const int steps = rk6_steps(rho_per_s, config_.period_s);
    return rk6_integrate(x, config_.period_s / steps, steps, rhs);
  }
  return integrate(x, config_.period_s / config_.rk4_substeps, config_.rk4_substeps, rhs);
}

template <bool smooth, typename VoltageLaw>
void InductionMotorPlant::integrate_voltage_fed(const VoltageLaw& voltage_of_state,
                                                double load_Nm) noexcept {
  const auto rhs = [&](const StateVector& x) {
    return voltage_fed_derivative(x, voltage_of_state(x), load_Nm);
  };
  state_ = unpack(integrate_period<smooth>(pack(state_), rhs));
  time_s_ += config_.period_s;
}

void InductionMotorPlant::step_voltage(const Vec2& u_s_alphabeta_V, double load_Nm) noexcept {
  integrate_voltage_fed<true>([&](const StateVector&) { return u_s_alphabeta_V; }, load_Nm);
}

void InductionMotorPlant::step_voltage(const Vec2& u_s_alphabeta_V,
                                       const CurrentDependentVoltage& error,
                                       double load_Nm) noexcept {
  // The inverter's error switches with the current's sign: RK4 with its small steps.
  integrate_voltage_fed<false>(
      [&](const StateVector& x) -> Vec2 {
        return u_s_alphabeta_V + error.error_V(constrained(x.segment<2>(2)));
      },
      load_Nm);
}

void InductionMotorPlant::step_voltage_segments(const VoltageSegment* segments,
                                                std::size_t count, double load_Nm) noexcept {
  const double h_max = config_.period_s / config_.rk4_substeps;
  StateVector x = pack(state_);
  // Integrals of I and |I|^2 over the period, the current taken linear over each step.
  Vec2 sum_A_s = Vec2::Zero();
  double sum_sq_A2_s = 0.0, total_s = 0.0;
  Vec2 current = constrained(x.segment<2>(2));
  for (std::size_t s = 0; s < count; ++s) {
    const VoltageSegment& segment = segments[s];
    const int steps = std::max(1, int(std::ceil(segment.duration_s / h_max - 1e-9)));
    const double h = segment.duration_s / steps;
    const auto rhs = [&](const StateVector& y) {
      return voltage_fed_derivative(y, segment.u_alphabeta_V, load_Nm);
    };
    for (int i = 0; i < steps; ++i) {
      x = integrate(x, h, 1, rhs);
      const Vec2 next = constrained(x.segment<2>(2));
      sum_A_s += 0.5 * h * (current + next);
      // |I|^2 of the straight line between the two ends, integrated exactly (the trapezoid of
      // the squares would count a ramp's square 3x over a step as long as the ramp).
      sum_sq_A2_s +=
          h * (current.squaredNorm() + current.dot(next) + next.squaredNorm()) / 3.0;
      total_s += h;
      current = next;
    }
  }
  state_ = unpack(x);
  time_s_ += config_.period_s;
  if (total_s > 0.0) {
    const Vec2 mean_A = sum_A_s / total_s;
    period_ripple_sq_A2_ = std::max(sum_sq_A2_s / total_s - mean_A.squaredNorm(), 0.0);
  }
}

namespace {

/// Feedback (2): u = sigma p w J (I + beta Phi) + e^{p th J} v~.
Vec2 feedback_2(const control::VoltageFedConstantsIn<double>& k, int pole_pairs, const Vec2& flux,
                const Vec2& current, double omega, double theta, const Vec2& v_AB_V) {
  const double p = pole_pairs;
  return k.sigma_H * p * omega * control::J_times<double>(current + k.beta_per_H * flux) +
         control::Rotation<double>::from_angle(p * theta).apply(v_AB_V);
}

}  // namespace

Vec2 InductionMotorPlant::analog_feedback_voltage_V(const Vec2& v_AB_V) const noexcept {
  return feedback_2(k_, motor_.pole_pairs, state_.flux_r_alphabeta_Wb, state_.i_s_alphabeta_A,
                    state_.omega_mech_rad_s, state_.theta_mech_rad, v_AB_V);
}

void InductionMotorPlant::step_analog_feedback(const Vec2& v_AB_V, double load_Nm) noexcept {
  integrate_voltage_fed<true>(
      [&](const StateVector& x) -> Vec2 {
        return feedback_2(k_, motor_.pole_pairs, x.segment<2>(0), x.segment<2>(2), x(4), x(5),
                          v_AB_V);
      },
      load_Nm);
}

double InductionMotorPlant::shaft_torque_Nm(double omega_rad_s, double load_Nm) const noexcept {
  double brake_Nm = 0.0;
  if (brake_Nm_ > 0.0) {
    const double h_s = config_.period_s / config_.rk4_substeps;
    const double omega_eps = brake_Nm_ * h_s / motor_.J_kgm2;
    brake_Nm = brake_Nm_ * std::clamp(omega_rad_s / omega_eps, -1.0, 1.0);
  }
  return -motor_.friction_Nms * omega_rad_s - load_Nm - brake_Nm;
}

void InductionMotorPlant::step_current_fed(const Vec2& i_s_AB_A, double load_Nm) noexcept {
  // The current is algebraic, I = e^{p th J} i_AB; only Phi, w and th are integrated. The
  // current slots of the state vector carry I and have zero derivative in the integrator.
  const double p = motor_.pole_pairs;
  const auto current_at = [&](double theta_mech_rad) {
    return control::Rotation<double>::from_angle(p * theta_mech_rad).apply(i_s_AB_A);
  };
  const auto rhs = [&](const StateVector& x) {
    const Vec2 flux = x.segment<2>(0);
    const Vec2 current = current_at(x(5));
    const double torque = torque_Nm(current, flux);
    StateVector dx;
    dx.segment<2>(0) = -k_.alpha_per_s * flux + p * x(4) * control::J_times(flux) +
                       k_.alpha_per_s * motor_.Lm_H * current;
    dx.segment<2>(2).setZero();
    dx(4) = (torque + shaft_torque_Nm(x(4), load_Nm)) * per_J_kgm2_;
    dx(5) = x(4);
    return dx;
  };
  StateVector x = integrate_period<true>(pack(state_), rhs);
  x.segment<2>(2) = current_at(x(5));
  state_ = unpack(x);
  time_s_ += config_.period_s;
}

}  // namespace imd::sim
