// Branches of the discrete sliding-mode law (paper 000, Section III), checked against the exact
// sampled model: deadbeat tracking, the saturated speed channel, a negative discriminant, the
// saturated flux channel, and a singular B_k refused at zero flux.
#include <gtest/gtest.h>

#include <cmath>

#include "control/dsmc.hpp"
#include "control/voltage_fed_model.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kDelta_s = 1e-4;

class DsmcTest : public ::testing::Test {
 protected:
  MotorParameters motor = test::test_motors()[0].parameters;  // paper 000 motor
  VoltageFedCoefficients coefficients = discretize_voltage_fed(motor, kDelta_s);
  VoltageFedModel<double> model{coefficients};
  Dsmc<double> dsmc{coefficients, DsmcConfig{}};

  /// A magnetized running state: flux 0.2 Wb^2 along A, a torque-producing current.
  RotorFrameState<double> running() const {
    RotorFrameState<double> x;
    x.flux_r_AB_Wb = {std::sqrt(0.2), 0.0};
    x.i_s_AB_A = {std::sqrt(0.2) / motor.Lm_H, 2.0};
    x.omega_mech_rad_s = 50.0;
    x.theta_mech_rad = 1.0;
    return x;
  }
  DsmcInput<double> input_for(const RotorFrameState<double>& x, double omega_ref, double flux2_ref,
                              double load_Nm) const {
    DsmcInput<double> in;
    in.flux_r_AB_Wb = x.flux_r_AB_Wb;
    in.i_s_AB_A = x.i_s_AB_A;
    in.omega_mech_rad_s = x.omega_mech_rad_s;
    in.load_Nm = load_Nm;
    in.omega_ref_next_rad_s = omega_ref;
    in.flux2_ref_next_Wb2 = flux2_ref;
    return in;
  }
  /// A disk of 300 V around the origin: an arbitrary but realistic voltage budget.
  static InputDisk<double> disk_300V() { return {Vec2<double>::Zero(), 300.0}; }
};

// The law is deadbeat on the exact model: both outputs reach their references in one step.
// Rounding: v~ = B^-1 w with |B^-1| ~ 1e6 and w ~ 1e-2 loses about 6 digits against w, and
// the outputs recover them through B; 1e-9 relative is a safe bound for double.
TEST_F(DsmcTest, UnlimitedLawIsDeadbeatOnTheExactModel) {
  const auto x = running();
  const double load_Nm = 0.7;
  const auto out = dsmc.step(input_for(x, 50.02, 0.2001, load_Nm));
  ASSERT_EQ(out.status, DsmcStatus::ok);
  EXPECT_FALSE(out.speed_saturated);
  EXPECT_FALSE(out.flux_saturated);
  EXPECT_GE(out.discriminant, 0.0);
  const auto next = model.predict(x, out.v_AB_V, load_Nm);
  EXPECT_NEAR(next.omega_mech_rad_s, 50.02, 1e-9 * 50.0);
  EXPECT_NEAR(next.flux_r_AB_Wb.squaredNorm(), 0.2001, 1e-9 * 0.2);
}

TEST_F(DsmcTest, SaturatedSpeedChannelStaysInTheDiskAndKeepsTheFlux) {
  const auto x = running();
  auto in = input_for(x, 80.0, 0.2, 0.0);  // a 30 rad/s step: impossible in one period
  in.feasible = disk_300V();
  const auto out = dsmc.step(in);
  ASSERT_EQ(out.status, DsmcStatus::ok);
  EXPECT_TRUE(out.speed_saturated);
  EXPECT_FALSE(out.flux_saturated);
  EXPECT_TRUE(in.feasible.contains(out.v_AB_V, 1e-9));
  EXPECT_GT(out.w_eq_alpha, out.w_alpha);  // pushed in the right direction, but less
  EXPECT_GT(out.w_alpha, 0.0);
  const auto next = model.predict(x, out.v_AB_V, 0.0);
  EXPECT_GT(next.omega_mech_rad_s, model.predict(x, {0.0, 0.0}, 0.0).omega_mech_rad_s);
  // Flux priority: the flux is still deadbeat. Its control was solved for the speed channel
  // before the last clamp; the mismatch enters through b1^2 |v~|^2 ~ (8e-7 * 300)^2 = 6e-8.
  EXPECT_NEAR(next.flux_r_AB_Wb.squaredNorm(), 0.2, 1e-7);
}

TEST_F(DsmcTest, NegativeDiscriminantUsesTheMinimiserOfTheFluxError) {
  // A 20 rad/s speed step in one period needs |v~| ~ 1e6 V, whose b1^2 |v~|^2 alone exceeds
  // the flux reference: no input reaches S2 = 0 and the discriminant is negative.
  const auto x = running();
  const auto out = dsmc.step(input_for(x, 70.0, 0.2, 0.0));
  ASSERT_EQ(out.status, DsmcStatus::ok);
  ASSERT_LT(out.discriminant, 0.0);
  const auto next = model.predict(x, out.v_AB_V, 0.0);
  const double s2 = next.flux_r_AB_Wb.squaredNorm() - 0.2;
  // S2_{k+1} = a w^2 + b w + c is least at the vertex, where it equals -D/(4a) > 0; a is
  // recovered from the vertex w = -b/(2a) with b = 1 - (small): check the value through c.
  EXPECT_GT(s2, 0.0);
  EXPECT_LT(s2, out.c_k);  // the paper's -b/a would leave exactly c_k
  EXPECT_NEAR(next.omega_mech_rad_s, 70.0, 1e-9 * 70.0);  // speed channel unaffected
}

TEST_F(DsmcTest, SaturatedFluxChannelMovesTowardsTheReference) {
  const auto x = running();
  auto in = input_for(x, 50.0, 0.8, 0.0);  // quadruple the squared flux: not in one period
  in.feasible = disk_300V();
  const auto out = dsmc.step(in);
  ASSERT_EQ(out.status, DsmcStatus::ok);
  EXPECT_TRUE(out.flux_saturated);
  EXPECT_TRUE(in.feasible.contains(out.v_AB_V, 1e-9));
  const auto next = model.predict(x, out.v_AB_V, 0.0);
  const auto coasting = model.predict(x, {0.0, 0.0}, 0.0);
  EXPECT_GT(next.flux_r_AB_Wb.squaredNorm(), coasting.flux_r_AB_Wb.squaredNorm());
  // The flux channel took the whole disk in the direction of the flux: the largest increase
  // that 300 V can give, b1 300 V along Phi.
  const double best =
      (coasting.flux_r_AB_Wb + coefficients.b1 * 300.0 * coasting.flux_r_AB_Wb.normalized())
          .squaredNorm();
  EXPECT_NEAR(next.flux_r_AB_Wb.squaredNorm(), best, 1e-6 * best);
}

TEST_F(DsmcTest, OffCentreDiskBoundsTheInputExactly) {
  // The voltage disk of a running motor is centred at -sigma p w J (I~ + beta Phi~), not at 0.
  // A saturated input must lie on that disk's boundary, not merely near the origin.
  const auto x = running();
  for (const Vec2<double>& centre : {Vec2<double>(-40.0, 25.0), Vec2<double>(60.0, -80.0)}) {
    auto in = input_for(x, 80.0, 0.2, 0.0);  // saturates the speed channel
    in.feasible = {centre, 120.0};
    const auto out = dsmc.step(in);
    ASSERT_EQ(out.status, DsmcStatus::ok);
    ASSERT_TRUE(out.speed_saturated);
    // On the boundary: the chord clamp is exact up to the rounding of v~ = B^-1 w, whose entries
    // (~1e6) amplify rounding of w (~1e-16 relative) to ~1e-9 V; 1e-6 V leaves margin.
    EXPECT_NEAR((out.v_AB_V - centre).norm(), 120.0, 1e-6) << centre.transpose();
    // And the speed gained is the most the disk allows along lambda1 for this flux control:
    // no input of the chord gives more (checked on a fine sweep of the boundary).
    const double gained = model.predict(x, out.v_AB_V, 0.0).omega_mech_rad_s;
    const double flux_next = model.predict(x, out.v_AB_V, 0.0).flux_r_AB_Wb.squaredNorm();
    for (int i = 0; i < 3600; ++i) {
      const double a = i * 2 * 3.141592653589793 / 3600;
      const Vec2<double> v = centre + 120.0 * Vec2<double>(std::cos(a), std::sin(a));
      const auto next = model.predict(x, v, 0.0);
      if (std::abs(next.flux_r_AB_Wb.squaredNorm() - flux_next) < 1e-7) {
        EXPECT_LE(next.omega_mech_rad_s, gained + 1e-6);
      }
    }
  }
}

// The input is solved first and the channels' ranges over the disk are computed only within a
// thousandth of the radius of its edge. Inside, the result must be the unlimited law's to the
// bit: well inside by the shortcut, near the edge because the ranges contain w and the clamps
// leave it. Just outside, the input is clamped onto the edge (to the rounding of B^-1 w, as
// above). The test holds the contract; it cannot tell which path was taken.
TEST_F(DsmcTest, AnInputInsideTheDiskIsTheUnlimitedLawsOwn) {
  const auto x = running();
  auto in = input_for(x, 50.02, 0.2001, 0.7);
  const auto free = dsmc.step(in);
  ASSERT_EQ(free.status, DsmcStatus::ok);
  const Vec2<double> centre(-40.0, 25.0);
  const double distance = (free.v_AB_V - centre).norm();
  for (const double radius : {2.0 * distance, distance * 1.0005, distance * 0.99}) {
    in.feasible = {centre, radius};
    const auto out = dsmc.step(in);
    ASSERT_EQ(out.status, DsmcStatus::ok);
    if (radius > distance * 1.001) {  // well inside: the shortcut
      EXPECT_EQ(out.v_AB_V, free.v_AB_V);
      EXPECT_FALSE(out.speed_saturated || out.flux_saturated);
    } else if (radius > distance) {  // inside, near the edge: the ranges leave it
      EXPECT_EQ(out.v_AB_V, free.v_AB_V);
      EXPECT_FALSE(out.speed_saturated || out.flux_saturated);
    } else {  // outside: clamped onto the edge
      EXPECT_TRUE(out.speed_saturated || out.flux_saturated);
      EXPECT_NEAR((out.v_AB_V - centre).norm(), radius, 1e-6);
    }
  }
}

TEST_F(DsmcTest, OffCentreDiskBoundsTheFluxChannel) {
  // A flux step the disk cannot deliver: the flux channel takes the disk's point that raises
  // |Phi_{k+1}|^2 most, c + r m/|m| with m = a11 Phi + a12 I (the flux without input).
  const auto x = running();
  const Vec2<double> m = coefficients.a11 * x.flux_r_AB_Wb + coefficients.a12 * x.i_s_AB_A;
  for (const Vec2<double>& centre : {Vec2<double>(-40.0, 25.0), Vec2<double>(60.0, -80.0)}) {
    auto in = input_for(x, 50.0, 0.8, 0.0);
    in.feasible = {centre, 120.0};
    const auto out = dsmc.step(in);
    ASSERT_EQ(out.status, DsmcStatus::ok);
    ASSERT_TRUE(out.flux_saturated);
    EXPECT_NEAR((out.v_AB_V - centre).norm(), 120.0, 1e-6);
    const Vec2<double> best_v = centre + 120.0 * m.normalized();
    const double best = model.predict(x, best_v, 0.0).flux_r_AB_Wb.squaredNorm();
    EXPECT_NEAR(model.predict(x, out.v_AB_V, 0.0).flux_r_AB_Wb.squaredNorm(), best, 1e-6 * best);
  }
}

TEST_F(DsmcTest, ReachingLawsScaleTheErrors) {
  // e_{k+1} = pole e_k for both outputs, on the exact model, with no limit.
  const Dsmc<double> law(coefficients, DsmcConfig{1e-3, 0.9, 0.8});
  auto x = running();
  auto in = input_for(x, 52.0, 0.21, 0.3);
  in.omega_ref_rad_s = 52.0;  // speed error at k: 50 - 52 = -2
  in.flux2_ref_Wb2 = 0.21;    // flux error at k: 0.2 - 0.21 = -0.01
  const auto out = law.step(in);
  ASSERT_EQ(out.status, DsmcStatus::ok);
  const auto next = model.predict(x, out.v_AB_V, 0.3);
  // Deadbeat on the shifted targets, so the same rounding bound as the unlimited law (1e-9 of
  // the speed, 1e-9 of the squared flux ~ 2e-10).
  EXPECT_NEAR(next.omega_mech_rad_s - 52.0, 0.9 * -2.0, 1e-9);
  EXPECT_NEAR(next.flux_r_AB_Wb.squaredNorm() - 0.21, 0.8 * -0.01, 1e-10);
}

TEST_F(DsmcTest, SingularBkIsRefusedAtZeroFlux) {
  RotorFrameState<double> x;  // unmagnetized: B_k = 0
  for (const double current_A : {0.0, 3.0}) {
    x.i_s_AB_A = {current_A, 0.0};
    const auto out = dsmc.step(input_for(x, 10.0, 0.2, 0.0));
    EXPECT_EQ(out.status, DsmcStatus::singular);
    EXPECT_EQ(out.v_AB_V, Vec2<double>::Zero());
    EXPECT_FALSE(std::isnan(out.det_B));
  }
  // NaN in the state is refused as well, rather than reaching the output.
  x.flux_r_AB_Wb = {std::nan(""), 0.0};
  EXPECT_EQ(dsmc.step(input_for(x, 10.0, 0.2, 0.0)).status, DsmcStatus::singular);
}

TEST_F(DsmcTest, StableRootKeepsFloatAccurate) {
  // For a small flux correction the root of (10) is tiny against b ~ 1: (-b + sqrt(D)) / (2a)
  // cancels. The law in float must still be deadbeat to float accuracy on the flux.
  const Dsmc<float> dsmc_f(coefficients, DsmcConfig{});
  const auto x = running();
  const auto in = input_for(x, 50.001, 0.20001, 0.0);
  DsmcInput<float> in_f;
  in_f.flux_r_AB_Wb = in.flux_r_AB_Wb.cast<float>();
  in_f.i_s_AB_A = in.i_s_AB_A.cast<float>();
  in_f.omega_mech_rad_s = float(in.omega_mech_rad_s);
  in_f.omega_ref_next_rad_s = float(in.omega_ref_next_rad_s);
  in_f.flux2_ref_next_Wb2 = float(in.flux2_ref_next_Wb2);
  const auto out_f = dsmc_f.step(in_f);
  const auto out_d = dsmc.step(in);
  ASSERT_EQ(out_f.status, DsmcStatus::ok);
  // w_beta ~ 1e-5 Wb^2: relative float error of a few 1e-7 gives 1e-11 Wb^2 absolute; the naive
  // form would lose about log10(1/|w_beta|) = 5 digits.
  EXPECT_NEAR(out_f.w_beta, out_d.w_beta, 1e-5 * std::abs(out_d.w_beta));
  const auto next = model.predict(x, out_f.v_AB_V.cast<double>(), 0.0);
  EXPECT_NEAR(next.flux_r_AB_Wb.squaredNorm(), 0.20001, 1e-6 * 0.2);
}

}  // namespace
}  // namespace imd::control
