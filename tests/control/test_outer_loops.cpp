// Outer loops of the current-fed drive: the flux loop of paper 001's Fig. 5, and the speed PI.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "control/current_fed_model.hpp"
#include "control/flux_outer_loop.hpp"
#include "control/speed_pi.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

TEST(FluxOuterLoop, PlacesADoublePole) {
  const auto c = discretize_current_fed(test::test_motors()[1].parameters, 1e-3);
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
  // A large error saturates at the limit; the integrator does not grow meanwhile.
  for (int k = 0; k < 5000; ++k) EXPECT_LE(std::abs(pi.step(100.0, 0.0)), 240.0);
  EXPECT_TRUE(pi.saturated());
  // When the error reverses, the output is the proportional part alone: Kp * (-1) = -20.5 N m.
  // A wound-up integral (up to the 240 N m clamp) would keep it near +219 N m.
  const double after = pi.step(0.0, 1.0);
  EXPECT_NEAR(after, -0.41 * 50.0 * 1.0, 0.1);
  EXPECT_FALSE(pi.saturated());
}

TEST(SpeedPi, UndoTakesBackTheLastIntegration) {
  // A later stage trimmed the torque: the step's integration is taken back.
  SpeedPi<double> pi(design_speed_pi(0.41, 50.0, 240.0, 1e-3));
  const double first = pi.step(1.0, 0.0);  // Kp e + 0 (the integral is used before it grows)
  pi.undo_last_integration();
  EXPECT_DOUBLE_EQ(pi.step(1.0, 0.0), first);  // the same: nothing was integrated
  const double third = pi.step(1.0, 0.0);
  EXPECT_GT(third, first);  // without the undo the integral grows
}

TEST(FluxOuterLoop, StepRealisesTheDesignedClosedLoop) {
  // Drive step() on the magnitude relation it inverts (aligned fluxes, no slip): the error must
  // obey the double-pole recurrence e(k+2) - 2 z e(k+1) + z^2 e(k) = 0, z = exp(-T0/tau).
  const double e = 0.9978351639822989, z = std::exp(-0.1);
  FluxOuterLoop<double> loop(e, place_flux_outer_loop(e, 1e-3, 0.01));
  double flux = std::sqrt(0.97);
  std::vector<double> error;
  for (int k = 0; k < 40; ++k) {
    error.push_back(1.0 - flux * flux);
    flux = next_flux(flux, loop.step(1.0, flux * flux), e, 0.0);
  }
  for (int k = 5; k + 2 < 40; ++k) {
    EXPECT_NEAR(error[k + 2] - 2 * z * error[k + 1] + z * z * error[k], 0.0, 1e-12) << k;
  }
  EXPECT_LT(std::abs(error.back()), 0.03 * 0.1);  // decayed by (1 + 39 * 0.1) z^39 ~ 0.1
}

TEST(FluxOuterLoop, DoesNotWindUpWhileTheFluxShrinksAtItsFastest) {
  // The reference drops from 1 to 0.01 Wb^2: the loop asks for the fastest decay, the floor
  // e^2 F (v2 = 0, no current), for as long as F is above the reference. Then the reference
  // comes back to 1. The flux must turn at once: v2 > 0 at the first step the error is
  // positive. An integrator that kept winding down at the floor held v2 at 0 for seconds (the
  // IOL's stator flux then collapsed towards the law's singular state in the soak).
  const double e = 0.9978351639822989;
  FluxOuterLoop<double> loop(e, place_flux_outer_loop(e, 1e-3, 0.01));
  double flux = 1.0;
  for (int k = 0; k < 1000; ++k) {  // 1 s: F = e^2000 ~ 0.013, still above 0.01
    const double v2 = loop.step(0.01, flux * flux);
    // At the floor throughout: v2 = sqrt(F) sqrt(e^2 F) - e F is zero but for the rounding of
    // two products of magnitude F <= 1 (a few 2^-53).
    ASSERT_NEAR(v2, 0.0, 1e-15) << k;
    flux = next_flux(flux, v2, e, 0.0);
  }
  ASSERT_GT(flux * flux, 0.01);
  const double F = flux * flux;
  const double v2 = loop.step(1.0, F);
  // The linear design's first step from an integrator the floor left at zero:
  // v2_linear = (1 - e) + Kp (1 - F).
  const FluxOuterLoopGains g = place_flux_outer_loop(e, 1e-3, 0.01);
  const double intended = e * F + (1.0 - e) + g.kp * (1.0 - F);
  // The same arithmetic in another order: only rounding (terms below 1) separates the two.
  EXPECT_NEAR(v2, std::sqrt(F) * std::sqrt(intended) - e * F, 1e-12);
}

TEST(SpeedPi, ClosedLoopOnTheExactSpeedModelRejectsALoadStep) {
  // The speed row of paper 001's exact model, torque applied one period late (y1(k+1) = v1(k)).
  const auto motor = test::test_motors()[1].parameters;
  const auto c = discretize_current_fed(motor, 1e-3);
  const CurrentFedModel<double> model(c);
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
