// Outer loops of the current-fed drive: the flux loop of paper 001's Fig. 5, and the speed PI.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "control/exact_model_001.hpp"
#include "control/flux_outer_loop.hpp"
#include "control/speed_pi.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

TEST(FluxOuterLoop, PlacesADoublePole) {
  const auto c = discretize_seed001(test::test_motors()[1].parameters, 1e-3);
  const auto gains = place_flux_outer_loop(c.flux_decay, 1e-3, 0.01);
  // Closed loop of F(k+1) = e F + v2, v2 = (1 - e) F_ref + Kp (F_ref - F) + I, I += Ki (F_ref - F).
  Eigen::Matrix2d loop;
  loop << c.flux_decay - gains.kp, 1.0, -gains.ki, 1.0;
  const double z = std::exp(-0.1);
  // A double root: the characteristic polynomial's coefficients, not the (ill-conditioned)
  // eigenvalues.
  EXPECT_NEAR(loop.trace(), 2 * z, 1e-12);
  EXPECT_NEAR(loop.determinant(), z * z, 1e-12);
}

/// Stator-flux magnitude at k+1 when the linearization delivers y2(k+1) = v2 and successive
/// flux samples turn by slip_T0 (steady slip in the rotor frame):
/// y2(k+1) = |phi(k+1)| |phi(k)| cos(slip_T0) - e |phi(k)|^2.
double next_flux(double flux_Wb, double v2, double e, double slip_T0) {
  return (v2 + e * flux_Wb * flux_Wb) / (flux_Wb * std::cos(slip_T0));
}

TEST(FluxOuterLoop, RemovesTheSteadyStateErrorOfEquation21) {
  // (21) assumes cos(w_sl T0) = 1. With slip, feed-forward alone settles above the reference
  // (the paper's "slight deviation"); the loop's integrator removes it.
  const double e = 0.9978351639822989, slip_T0 = 0.02;  // w_sl = 20 rad/s at T0 = 1 ms
  const double ref = 0.81;
  FluxOuterLoop<double> loop(e, place_flux_outer_loop(e, 1e-3, 0.01));
  double flux = 0.7, open_flux = 0.7;
  for (int k = 0; k < 3000; ++k) {
    flux = next_flux(flux, loop.step(ref, flux * flux), e, slip_T0);
    open_flux = next_flux(open_flux, (1.0 - e) * ref, e, slip_T0);
  }
  // Closed loop: the double pole at 0.905 leaves e^-300-small transients after 3 s.
  EXPECT_NEAR(flux * flux, ref, 1e-9);
  // Feed-forward alone: F = (1 - e) F_ref / (cos(w_sl T0) - e), 10 % high at this slip.
  const double open_expected = (1.0 - e) * ref / (std::cos(slip_T0) - e);
  EXPECT_NEAR(open_flux * open_flux, open_expected, 1e-3 * open_expected);
  EXPECT_GT(open_expected, 1.09 * ref);
}

TEST(SpeedPi, LimitsTorqueAndDoesNotWindUp) {
  SpeedPi<double> pi(design_speed_pi(0.41, 50.0, 240.0, 1e-3));
  // A large error saturates at the limit and the integrator stays bounded.
  for (int k = 0; k < 5000; ++k) EXPECT_LE(std::abs(pi.step(100.0, 0.0)), 240.0);
  EXPECT_TRUE(pi.saturated());
  // When the error reverses, the output leaves the limit at once (no wound-up integral).
  const double after = pi.step(0.0, 1.0);
  EXPECT_LT(after, 240.0);
  EXPECT_FALSE(pi.saturated());
}

TEST(SpeedPi, ClosedLoopOnTheExactSpeedModelRejectsALoadStep) {
  // The speed row of paper 001's exact model, torque applied one period late (y1(k+1) = v1(k)).
  const auto motor = test::test_motors()[1].parameters;
  const auto c = discretize_seed001(motor, 1e-3);
  const ExactModel001<double> model(c);
  SpeedPi<double> pi(design_speed_pi(motor.J_kgm2, 50.0, 240.0, 1e-3));
  double omega = 0.0, torque = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double load = k >= 1500 ? 100.0 : 0.0;
    const double command = pi.step(100.0, omega);
    // The torque decays inside the period (14); next_speed integrates that exactly.
    omega = model.next_speed(omega, torque, load);
    torque = command;
  }
  // Integral action removes the load's offset. At equilibrium the speed row gives the torque
  // command exactly: 0 = (d - 1) w + g_T T - g_L L (the torque decays inside the period, so
  // the command exceeds the load by the factor g_L / g_T = 1.001). Poles of the loop at
  // ~exp(-50 rad/s x t): 1.5 s after the step the transient is gone to far below 1e-6.
  const double expected_torque =
      (-c.load_to_speed * 100.0 - c.speed_decay_minus_one * 100.0) / c.torque_to_speed;
  EXPECT_NEAR(omega, 100.0, 1e-6);
  EXPECT_NEAR(torque, expected_torque, 1e-6);
}

}  // namespace
}  // namespace imd::control
