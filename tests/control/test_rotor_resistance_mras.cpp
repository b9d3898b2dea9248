// The reactive-power MRAS (control/rotor_resistance_mras.hpp) on the continuous plant of
// hal_sim: the motor is held at a constant speed (a large inertia) and fed the steady-state
// voltage of a chosen current and slip, so the data are the plant's own. On every test motor
// the estimate converges to the plant's Rr from 0.6x and 1.5x; at zero slip it stays put.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "control/rotor_resistance_mras.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

using V2 = Vec2<double>;

struct Outcome {
  double Rr_final_Ohm;
  double adapting_share;  ///< of the ticks
};

/// The motor at `speed_share` of its typical speed, fed the voltage that holds a current of
/// (i_d, i_q) = magnitude (1, tangent) / sqrt(1 + tangent^2) in the flux frame (slip
/// tangent x = i_q/i_d); the tracker starts from `scale` x Rr and runs `duration_s`.
template <typename Real = double>
Outcome run_motor(const test::TestMotor& tm, double tangent, double scale, double duration_s) {
  MotorParameters plant_motor = tm.parameters;
  plant_motor.J_kgm2 = 1e9;  // the speed stays where it is put
  plant_motor.friction_Nms = 0.0;
  const double T = 1e-4;
  sim::InductionMotorPlant plant(plant_motor, {T, 10});
  const MotorParameters& m = tm.parameters;
  const double rho = m.Rr_Ohm / m.Lr_H, sigma = m.Ls_H - m.Lm_H * m.Lm_H / m.Lr_H;
  const double i_d = tm.flux_Wb / m.Lm_H, i_q = tangent * i_d;
  const double omega = 0.5 * tm.speed_rad_s, omega_e = m.pole_pairs * omega + rho * tangent;
  // Steady state in the frame of the rotor flux, which turns at omega_e.
  const double u_d = m.Rs_Ohm * i_d - omega_e * sigma * i_q;
  const double u_q = m.Rs_Ohm * i_q + omega_e * m.Ls_H * i_d;
  sim::PlantState start;
  start.flux_r_alphabeta_Wb = {m.Lm_H * i_d, 0.0};
  start.i_s_alphabeta_A = {i_d, i_q};
  start.omega_mech_rad_s = omega;
  plant.set_state(start);

  MotorParameters model = m;
  model.Rr_Ohm = scale * m.Rr_Ohm;
  RotorResistanceMrasConfig config;
  config.sample_period_s = T;
  RotorResistanceMras<Real> mras(model, config, m.Rr_Ohm);
  V2 u_last = V2::Zero();
  double theta_last_rad = start.theta_mech_rad;
  int adapting = 0;
  const int ticks = static_cast<int>(duration_s / T);
  for (int k = 0; k < ticks; ++k) {
    const sim::PlantState& s = plant.state();
    const Rotation<double> rotor = Rotation<double>::from_angle(m.pole_pairs * s.theta_mech_rad);
    const V2 i_AB = rotor.apply_inverse(s.i_s_alphabeta_A);
    // The mean speed over the last period, as the encoder's counts give it (here exactly).
    const double omega_mean =
        k == 0 ? s.omega_mech_rad_s
               : std::remainder(s.theta_mech_rad - theta_last_rad, 2 * std::numbers::pi) / T;
    theta_last_rad = s.theta_mech_rad;
    mras.step(s.i_s_alphabeta_A.cast<Real>(), i_AB.cast<Real>(), Real(s.omega_mech_rad_s),
              Real(omega_mean), u_last.cast<Real>(), true);
    adapting += mras.adapting();
    // The voltage for [t_k, t_k+1], taken at the middle of the period (as SVPWM holds it).
    const Rotation<double> frame = Rotation<double>::from_angle(omega_e * (k + 0.5) * T);
    u_last = frame.apply(V2(u_d, u_q));
    plant.step_voltage(u_last, 0.0);
  }
  return {mras.Rr_Ohm(), double(adapting) / ticks};
}

double duration_for(const MotorParameters& m) {
  RotorResistanceMrasConfig c;
  // The adaptation's rate at x = 1 is 1/tau_c: 12 tau_c leave e^-12 of a 1.5x error.
  return 12.0 * RotorResistanceMras<double>::convergence_s(m, c);
}

TEST(RotorResistanceMras, ConvergesToThePlantsRotorResistanceOnEveryMotor) {
  for (const test::TestMotor& tm : test::test_motors()) {
    for (double scale : {0.6, 1.5}) {
      const Outcome r = run_motor(tm, 1.0, scale, duration_for(tm.parameters));
      // What is left is the approximation of the sampled data (the current's mean over the
      // period against the voltage held, the derivative from two samples): O((w_e T)^2) of Q,
      // below 0.1 % at these frequencies; 0.5 % leaves room for the filter's last ripple.
      EXPECT_NEAR(r.Rr_final_Ohm / tm.parameters.Rr_Ohm, 1.0, 5e-3)
          << tm.name << " from " << scale << "x";
      EXPECT_GT(r.adapting_share, 0.9) << tm.name;
    }
  }
}

TEST(RotorResistanceMras, ConvergesAtALightLoadSlowerAndStillToTheRightValue) {
  // x = 0.4: the rate is 2 x^2/(1 + x^2) = 0.28 of that at x = 1, so 4x the time.
  const test::TestMotor tm = test::test_motors()[2];
  const Outcome r = run_motor(tm, 0.4, 1.5, 4.0 * duration_for(tm.parameters));
  EXPECT_NEAR(r.Rr_final_Ohm / tm.parameters.Rr_Ohm, 1.0, 5e-3);
}

TEST(RotorResistanceMras, FreezesWithoutSlip) {
  // At no load Q does not depend on Rr: the estimate must not move, whatever it is.
  for (const test::TestMotor& tm : test::test_motors()) {
    const Outcome r = run_motor(tm, 0.0, 1.5, 1.0);
    EXPECT_EQ(r.Rr_final_Ohm, 1.5 * tm.parameters.Rr_Ohm) << tm.name;
    EXPECT_EQ(r.adapting_share, 0.0) << tm.name;
  }
}

TEST(RotorResistanceMras, BrakingConvergesToo) {
  // Negative slip (generating): x < 0 and Q still grows with Rr.
  const test::TestMotor tm = test::test_motors()[3];
  const Outcome r = run_motor(tm, -1.0, 0.6, duration_for(tm.parameters));
  EXPECT_NEAR(r.Rr_final_Ohm / tm.parameters.Rr_Ohm, 1.0, 5e-3);
}

TEST(RotorResistanceMras, ConvergesInFloatOnTheSlowestRotor) {
  // The 37 kW motor's gain per tick is T/tau_c = 5e-5, the smallest of the test motors: the
  // float estimate (the MCU's) must converge as the double one does. (Near convergence a step
  // gain x relative falls below float's 2^-24 against Rr; the tracker sums the steps before it
  // applies them, so that they are not rounded away.)
  const test::TestMotor tm = test::test_motors()[1];
  for (double scale : {0.6, 1.5}) {
    const Outcome single = run_motor<float>(tm, 1.0, scale, duration_for(tm.parameters));
    EXPECT_NEAR(single.Rr_final_Ohm / tm.parameters.Rr_Ohm, 1.0, 5e-3) << scale;
  }
}

/// A synthetic steady state on the paper-000 motor in the rotor frame (current and flux turning
/// at the slip, the rotor at 100 rad/s), for a tracker whose model starts at 1.5 x Rr.
struct SyntheticSteadyState {
  test::TestMotor tm = test::test_motors()[0];
  RotorResistanceMrasConfig config;
  MotorParameters model = with_Rr(tm.parameters, 1.5 * tm.parameters.Rr_Ohm);
  double omega = 100.0;

  static MotorParameters with_Rr(MotorParameters m, double Rr_Ohm) {
    m.Rr_Ohm = Rr_Ohm;
    return m;
  }
  template <typename Real>
  RotorResistanceMras<Real> tracker() const {
    return RotorResistanceMras<Real>(model, config, tm.parameters.Rr_Ohm);
  }
  /// Tick k's input to `mras`.
  template <typename Real>
  void step(RotorResistanceMras<Real>& mras, int k) const {
    const MotorParameters& m = tm.parameters;
    const double i_d = tm.flux_Wb / m.Lm_H, slip = m.Rr_Ohm / m.Lr_H;
    const double t = k * 1e-4, angle = slip * t, theta = omega * t * m.pole_pairs;
    const V2 i_AB = Rotation<double>::from_angle(angle).apply(V2(i_d, i_d));
    const V2 i_ab = Rotation<double>::from_angle(theta).apply(i_AB);
    const V2 u = Rotation<double>::from_angle(theta + angle).apply(V2(10.0, 300.0));
    mras.step(i_ab.cast<Real>(), i_AB.cast<Real>(), Real(omega), Real(omega), u.cast<Real>(), true);
  }
};

TEST(RotorResistanceMras, FloatFollowsDouble) {
  // The same run in float (the MCU's arithmetic) on the paper-000 motor.
  const SyntheticSteadyState run;
  RotorResistanceMras<float> single = run.tracker<float>();
  RotorResistanceMras<double> twice = run.tracker<double>();
  for (int k = 0; k < 20000; ++k) {
    run.step(single, k);
    run.step(twice, k);
  }
  // float's 2^-24 on each product, accumulated through the filters: 1e-4 relative.
  EXPECT_NEAR(single.Rr_Ohm() / twice.Rr_Ohm(), 1.0, 1e-4);
}

// The filters and the adaptation run once a block (mras_block_ticks(): tau/32, at most 64
// ticks). A tracker that takes over from another in the middle of a block (a retuned model on
// the same motor) must carry on exactly where it left off: its sums, its count and its filters.
TEST(RotorResistanceMras, TakingOverInTheMiddleOfABlockChangesNothing) {
  const SyntheticSteadyState run;
  RotorResistanceMras<double> alone = run.tracker<double>();
  const int block = alone.block_ticks();
  // The model's tau_r (its Rr 1.5 times the motor's: 27 ms) over 32 periods of 100 us.
  EXPECT_EQ(block, mras_block_ticks(run.model.Lr_H / run.model.Rr_Ohm, run.config.sample_period_s));
  EXPECT_EQ(block, 8);
  std::optional<RotorResistanceMras<double>> swapped(run.tracker<double>());
  for (int k = 0; k < 20000; ++k) {
    if (k % 997 == 0 && k > 0) {  // 997, prime: the swaps fall at every place within a block
      RotorResistanceMras<double> next = run.tracker<double>();
      next.continue_from(*swapped);
      swapped.emplace(next);
    }
    run.step(alone, k);
    run.step(*swapped, k);
    ASSERT_EQ(alone.Rr_Ohm(), swapped->Rr_Ohm()) << k;
    ASSERT_EQ(alone.q_reference_var(), swapped->q_reference_var()) << k;
  }
  EXPECT_NE(alone.Rr_Ohm(), run.model.Rr_Ohm);  // it adapted
}

}  // namespace
}  // namespace imd::control
