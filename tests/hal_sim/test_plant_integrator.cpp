// The plant's sixth-order integrator (hal_sim/plant_integrator.hpp) against RK4 at 10 us, the
// integrator every earlier result was computed with: on the six motors of the tests (0.55 to
// 37 kW, one to four pole pairs), in each input mode the sixth-order method serves (held
// voltages as the inverter's average, the analog feedback (2), the PWM off), with load steps,
// from rest and at field-weakening speeds.
//
// Tolerance. Both runs are also compared with RK4 at 1 us, whose truncation error is 1e-4 of
// RK4's at 10 us (h^4), so that each difference from it is that integrator's own error. The
// electrical modes have |lambda h| < 0.01 at 10 us here (the fastest: the 7 kW motor at twice
// its speed scale, |lambda| <= alpha + gamma + p |w| = 237 + 3 * 200 = 837 1/s, which the step
// rule of plant_integrator.hpp covers with two sixth-order steps per period), so RK4's local
// error is below (0.01)^5 / 5! = 8e-13 of the state per step. Summed over the run's 25 000
// steps with no damping credited that bounds RK4's error by 2e-8 only, too loose to test
// against; the run prints the error itself: up to 4.5e-10 of a state's scale (field weakening,
// analog feedback), 1e-14 to 2e-11 elsewhere.
//
// Two assertions per case:
// - rk6's error against the reference is no larger than RK4's at 10 us, or than the reference's
//   own rounding, whichever is larger. The reference takes N = 250 000 RK4 steps; each rounds
//   the state at least twice (the weighted sum and x + dx), 2 u = 2^-52 of its magnitude, and
//   the position and speed integrate what is not damped, so it may drift by up to
//   N 2^-52 = 5.6e-11 of the largest magnitude a state reaches over its scale. Below that floor
//   no comparison of two errors means anything (seed000 from rest, 8.5e-13 against
//   6.1e-13, and seed001 running, 7.2e-12 against 6.0e-12).
// - rk6 and RK4 at 10 us agree within 1e-9 of each state's scale. With rk6's error no larger than
//   RK4's the difference is at most twice RK4's own error, measured up to 4.5e-10: 1e-9 is that
//   twice with 10 % to spare, so that a regression in either integrator beyond the size of
//   RK4's known error fails. The sixth-order steps at twice the rule's radius (rho h = 0.1)
//   already miss it by a factor of four at 2.5x the speed scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>

#include "control/frames.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

constexpr double kPeriod_s = 1e-4;
constexpr int kPeriods = 2500;  // 0.25 s: magnetizing, acceleration and two load steps
constexpr int kFineSubsteps = 100;  // the reference: RK4 at 1 us

/// How a run drives the plant each period.
enum class Mode { pwm_average, analog_feedback, pwm_off };

struct Case {
  const char* name;
  Mode mode;
  double speed_start;  ///< times the motor's speed scale
  double flux_start;   ///< times the motor's flux scale
};

const Case kCases[] = {
    {"pwm_from_rest", Mode::pwm_average, 0.0, 0.0},
    {"pwm_running", Mode::pwm_average, 1.0, 1.0},
    {"pwm_field_weakening", Mode::pwm_average, 2.0, 0.5},
    {"analog_feedback", Mode::analog_feedback, 1.0, 1.0},
    {"pwm_off_coasting", Mode::pwm_off, 1.0, 1.0},
};

/// A pseudo-random +-10 % per period, as the PWM average of a drive moves from one period to the
/// next.
double wobble(int k) { return 0.1 * std::sin(12.9898 * k + 78.233 * std::sin(0.37 * k)); }

/// Stator voltage per unit of stator current in the steady state at electrical frequency
/// `omega_e_rad_s` and mechanical speed `omega_mech_rad_s` (the per-phase equivalent circuit).
double impedance_Ohm(const control::MotorParameters& m, double omega_e_rad_s,
                     double omega_mech_rad_s) {
  const std::complex<double> j(0.0, 1.0);
  const double slip_rad_s = omega_e_rad_s - m.pole_pairs * omega_mech_rad_s;
  const std::complex<double> rotor =
      slip_rad_s == 0.0 ? std::complex<double>(0.0)
                        : j * omega_e_rad_s * m.Lm_H *
                              (-j * slip_rad_s * m.Lm_H / (m.Rr_Ohm + j * slip_rad_s * m.Lr_H));
  return std::abs(m.Rs_Ohm + j * omega_e_rad_s * m.Ls_H + rotor);
}

struct Scales {
  double flux_Wb, current_A, speed_rad_s, theta_rad;
};

/// Largest |a - b| / scale over the run, per state (flux, current, speed, position).
struct Deviation {
  double flux = 0, current = 0, speed = 0, theta = 0;
  void add(const PlantState& a, const PlantState& b, const Scales& s) {
    flux = std::max(flux, (a.flux_r_alphabeta_Wb - b.flux_r_alphabeta_Wb).norm() / s.flux_Wb);
    current = std::max(current, (a.i_s_alphabeta_A - b.i_s_alphabeta_A).norm() / s.current_A);
    speed = std::max(speed, std::abs(a.omega_mech_rad_s - b.omega_mech_rad_s) / s.speed_rad_s);
    theta = std::max(theta, std::abs(a.theta_mech_rad - b.theta_mech_rad) / s.theta_rad);
  }
  double worst() const { return std::max({flux, current, speed, theta}); }
};

/// The input of one period, the same for every plant of a case.
struct Input {
  double omega_e_rad_s = 0.0;  ///< supply frequency (pwm_average)
  double amplitude_V = 0.0;    ///< supply amplitude, or |v~| (analog_feedback)
};

/// One period of the case's input on `plant`.
void drive_period(InductionMotorPlant& plant, const Case& c, int k, const Input& in,
                  double load_Nm) {
  const double scale = in.amplitude_V * (1.0 + wobble(k));
  switch (c.mode) {
    case Mode::pwm_average: {  // a supply of fixed frequency, its value at mid-period held
      const double phase = in.omega_e_rad_s * (k + 0.5) * kPeriod_s;
      plant.step_voltage(scale * Vec2(std::cos(phase), std::sin(phase)), load_Nm);
      break;
    }
    case Mode::analog_feedback:  // (2) with v~ rotating at 10 rad/s in the rotor frame
      plant.step_analog_feedback(
          scale * Vec2(std::cos(10.0 * k * kPeriod_s), std::sin(10.0 * k * kPeriod_s)), load_Nm);
      break;
    case Mode::pwm_off:
      plant.step_current_fed(Vec2::Zero(), load_Nm);
      break;
  }
}

TEST(PlantIntegrator, Rk6AgreesWithRk4At10usOnEveryMotorAndInput) {
  for (const test::TestMotor& motor : test::test_motors()) {
    const control::MotorParameters& m = motor.parameters;
    for (const Case& c : kCases) {
      SCOPED_TRACE(motor.name + " " + c.name);
      // The supply runs at the start speed plus a slip of 5 % of the speed scale (a
      // direct-on-line start from rest), at the amplitude that drives the current scale.
      const double omega_mech_rad_s = c.speed_start * motor.speed_rad_s;
      Input in;
      in.omega_e_rad_s = m.pole_pairs * (omega_mech_rad_s + 0.05 * motor.speed_rad_s);
      in.amplitude_V = motor.current_A * impedance_Ohm(m, in.omega_e_rad_s, omega_mech_rad_s);
      // Under (2) the rotor frame is linear and time-invariant (dPhi = -a Phi + a Lm I,
      // dI = a b Phi - g I + v / sigma): v~ at 10 rad/s for half the current scale, which
      // keeps the flux near its scale.
      if (c.mode == Mode::analog_feedback) {
        const control::VoltageFedConstants kc = control::derive_voltage_fed(m);
        const std::complex<double> s(0.0, 10.0);
        in.amplitude_V = 0.5 * motor.current_A * kc.sigma_H *
                         std::abs(s + kc.gamma_per_s - kc.alpha_per_s * kc.alpha_per_s *
                                                           kc.beta_per_H * m.Lm_H /
                                                           (s + kc.alpha_per_s));
      }
      const Scales scales{motor.flux_Wb, motor.current_A, motor.speed_rad_s,
                          motor.speed_rad_s * std::max(c.speed_start, 1.0) * kPeriods *
                              kPeriod_s};
      PlantState start;
      start.omega_mech_rad_s = omega_mech_rad_s;
      start.flux_r_alphabeta_Wb = {c.flux_start * motor.flux_Wb, 0.0};
      start.i_s_alphabeta_A = {c.flux_start * motor.flux_Wb / m.Lm_H, 0.0};
      start.theta_mech_rad = 0.3;
      InductionMotorPlant rk4(m, {kPeriod_s, 10, PlantIntegrator::rk4});
      InductionMotorPlant rk6(m, {kPeriod_s, 10, PlantIntegrator::rk6});
      InductionMotorPlant fine(m, {kPeriod_s, kFineSubsteps, PlantIntegrator::rk4});
      for (InductionMotorPlant* plant : {&rk4, &rk6, &fine}) plant->set_state(start);
      Deviation rk6_vs_rk4, rk4_error, rk6_error;
      double peak_current_A = 0.0, peak_flux_Wb = 0.0, peak_speed_rad_s = 0.0;
      for (int k = 0; k < kPeriods; ++k) {
        // Load steps: none, the motor's typical load, then half of it.
        const double load_Nm = k < kPeriods / 3 ? 0.0 : k < 2 * kPeriods / 3 ? motor.load_Nm
                                                                              : 0.5 * motor.load_Nm;
        for (InductionMotorPlant* plant : {&rk4, &rk6, &fine}) {
          drive_period(*plant, c, k, in, load_Nm);
        }
        rk6_vs_rk4.add(rk6.state(), rk4.state(), scales);
        rk4_error.add(rk4.state(), fine.state(), scales);
        rk6_error.add(rk6.state(), fine.state(), scales);
        peak_current_A = std::max(peak_current_A, rk4.state().i_s_alphabeta_A.norm());
        peak_flux_Wb = std::max(peak_flux_Wb, rk4.state().flux_r_alphabeta_Wb.norm());
        peak_speed_rad_s = std::max(peak_speed_rad_s, std::abs(rk4.state().omega_mech_rad_s));
      }
      std::printf("%-18s %-20s |rk6-rk4| %.1e (flux %.1e current %.1e speed %.1e theta %.1e); "
                  "error vs RK4 at 1 us: rk4 %.1e rk6 %.1e; peak %.3g A %.3g Wb, end %.4g rad/s\n",
                  motor.name.c_str(), c.name, rk6_vs_rk4.worst(), rk6_vs_rk4.flux,
                  rk6_vs_rk4.current, rk6_vs_rk4.speed, rk6_vs_rk4.theta, rk4_error.worst(),
                  rk6_error.worst(), peak_current_A, peak_flux_Wb, rk4.state().omega_mech_rad_s);
      EXPECT_LE(rk6_vs_rk4.flux, 1e-9);
      EXPECT_LE(rk6_vs_rk4.current, 1e-9);
      EXPECT_LE(rk6_vs_rk4.speed, 1e-9);
      EXPECT_LE(rk6_vs_rk4.theta, 1e-9);
      // rk6 at least as accurate as RK4 at 10 us, down to the reference's rounding floor (above).
      const double largest_magnitude = std::max(
          {1.0, peak_current_A / scales.current_A, peak_flux_Wb / scales.flux_Wb,
           peak_speed_rad_s / scales.speed_rad_s});
      const double rounding_floor =
          kPeriods * kFineSubsteps * std::numeric_limits<double>::epsilon() * largest_magnitude;
      EXPECT_LE(rk6_error.worst(), std::max(rk4_error.worst(), rounding_floor));
      // The states moved: a run that sat still would compare nothing.
      if (c.mode == Mode::pwm_off) {
        // No stator current: |Phi| decays as exp(-alpha t), to at most exp(-0.25 s / 0.46 s) =
        // 0.58 of its start for the slowest rotor (seed001, Lr / Rr = 0.46 s).
        EXPECT_LT(rk4.state().flux_r_alphabeta_Wb.norm(),
                  0.9 * start.flux_r_alphabeta_Wb.norm());
      } else {
        EXPECT_GT((rk4.state().i_s_alphabeta_A - start.i_s_alphabeta_A).norm() +
                      std::abs(rk4.state().omega_mech_rad_s - start.omega_mech_rad_s),
                  0.01 * (motor.current_A + motor.speed_rad_s));
      }
    }
  }
}

TEST(PlantIntegrator, NamesRoundTrip) {
  for (const PlantIntegrator i : {PlantIntegrator::rk4, PlantIntegrator::rk6}) {
    EXPECT_EQ(integrator_named(integrator_name(i)), i);
  }
  EXPECT_FALSE(integrator_named("euler"));
}

}  // namespace
}  // namespace imd::sim
