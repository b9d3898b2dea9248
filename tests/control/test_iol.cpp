// The input-output linearizing law of paper 001, Section 4, against the exact discrete model:
// decoupling, the determinant guard, and the cut to the currents the current loop reaches.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "control/current_fed_model.hpp"
#include "control/iol.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kT0_s = 1e-3;

class IolTest : public ::testing::Test {
 protected:
  MotorParameters motor = test::test_motors()[1].parameters;  // paper 001's 37 kW motor
  CurrentFedCoefficients coefficients = discretize_current_fed(motor, kT0_s);
  CurrentFedModel<double> model{coefficients};
  Iol<double> iol{coefficients, IolConfig{}};

  /// A magnetized operating point: stator flux ~0.9 Wb, 100 A of torque-producing current.
  IolInput<double> operating_point(double angle_rad, double torque_Nm, double flux2_Wb2) const {
    IolInput<double> in;
    const Vec2<double> d(std::cos(angle_rad), std::sin(angle_rad));
    in.flux_s_AB_Wb = 0.9 * d;
    in.i_s_AB_A = 30.0 * d + 100.0 * J_times<double>(d);
    in.torque_ref_Nm = torque_Nm;
    in.y2_ref = flux2_Wb2 * (1.0 - coefficients.flux_decay);  // (21)
    return in;
  }
};

TEST_F(IolTest, DecouplesTorqueAndSecondOutputExactly) {
  // (25): y1(k+1) = v1 and y2(k+1) = v2 on the exact model. u = B^-1 w with |B^-1| ~ 1e3 and
  // w ~ 1e2 loses three digits at most: 1e-12 relative is a safe bound in double.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi),
      torque(-240.0, 240.0), flux2(0.6, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const IolInput<double> in = operating_point(angle(rng), torque(rng), flux2(rng));
    const IolOutput<double> out = iol.step(in);
    ASSERT_EQ(out.status, IolStatus::ok);
    ASSERT_FALSE(out.torque_limited) << trial;
    const Vec2<double> flux_next =
        model.next_stator_flux(in.flux_s_AB_Wb, in.i_s_AB_A, out.i_next_AB_A);
    EXPECT_NEAR(model.torque_Nm(flux_next, out.i_next_AB_A), in.torque_ref_Nm, 1e-12 * 240.0);
    EXPECT_NEAR(iol.y2(flux_next, in.flux_s_AB_Wb), in.y2_ref, 1e-12 * std::abs(in.y2_ref));
  }
}

TEST_F(IolTest, ExcessiveTorqueIsSaturatedAndKeepsTheDeterminantNegative) {
  // phi_r(k+1) = 0.032 phi_s(k+1) + 0.966 phi_r(k) for this motor, and the torque at k+1 is
  // k n_p / (ls sigma) phi_r(k) x phi_s(k+1): from aligned fluxes a large torque only lengthens
  // phi_s(k+1) and det B stays negative. The danger is a state whose stator flux already leads
  // phi_r by a wide angle (50 degrees here), pushed further the same way.
  IolInput<double> in;
  in.flux_s_AB_Wb = {0.9, 0.0};
  const double lag = 50.0 * std::numbers::pi / 180;
  const Vec2<double> flux_r(0.8 * std::cos(lag), -0.8 * std::sin(lag));
  in.i_s_AB_A =
      (flux_r - coefficients.flux_decay * in.flux_s_AB_Wb) / coefficients.flux_from_i_now_H;
  ASSERT_NEAR((iol.modified_rotor_flux(in.flux_s_AB_Wb, in.i_s_AB_A) - flux_r).norm(), 0.0, 1e-12);
  in.torque_ref_Nm = 2000.0;
  in.y2_ref = 0.81 * (1.0 - coefficients.flux_decay);
  const IolOutput<double> out = iol.step(in);
  ASSERT_EQ(out.status, IolStatus::ok);
  EXPECT_TRUE(out.torque_limited);
  EXPECT_LT(out.torque_cmd_Nm, 2000.0);
  EXPECT_GT(out.torque_cmd_Nm, 0.0);  // the guard trims, it does not reverse
  ASSERT_TRUE(out.i_next_AB_A.allFinite());
  const Vec2<double> flux_next =
      model.next_stator_flux(in.flux_s_AB_Wb, in.i_s_AB_A, out.i_next_AB_A);
  const Vec2<double> flux_r_next = iol.modified_rotor_flux(flux_next, out.i_next_AB_A);
  const double cos_angle = flux_next.dot(flux_r_next) / (flux_next.norm() * flux_r_next.norm());
  // The bisection stops within 2^-30 of the boundary: cos 60 deg is met to ~1e-9.
  EXPECT_NEAR(cos_angle, 0.5, 1e-6);
  EXPECT_LT(out.det_B_next, 0.0);
  // Unsaturated, the same request would have made the fluxes (nearly) orthogonal.
  const IolOutput<double> unguarded =
      Iol<double>(coefficients, IolConfig{1.5707, 1.5184364492350666, 1e-3}).step(in);
  const Vec2<double> flux_free =
      model.next_stator_flux(in.flux_s_AB_Wb, in.i_s_AB_A, unguarded.i_next_AB_A);
  const Vec2<double> flux_r_free = iol.modified_rotor_flux(flux_free, unguarded.i_next_AB_A);
  EXPECT_LT(flux_free.dot(flux_r_free) / (flux_free.norm() * flux_r_free.norm()), 0.5);
  // The torque actually produced is the saturated command: decoupling still holds.
  EXPECT_NEAR(model.torque_Nm(flux_next, out.i_next_AB_A), out.torque_cmd_Nm,
              1e-9 * out.torque_cmd_Nm);
}

TEST_F(IolTest, NearlySingularStateIsRefusedWithoutDivision) {
  // det B_k = -k n_p ls sigma phi_s . phi_r = 0: a current that puts phi_r at right angles to
  // the stator flux, no flux at all, or a NaN. The law holds the current instead of dividing.
  IolInput<double> in;
  in.flux_s_AB_Wb = {0.9, 0.0};
  const Vec2<double> flux_r(0.0, 0.8);
  in.i_s_AB_A =
      (flux_r - coefficients.flux_decay * in.flux_s_AB_Wb) / coefficients.flux_from_i_now_H;
  in.torque_ref_Nm = 100.0;
  in.y2_ref = 0.002;
  const IolOutput<double> orthogonal = iol.step(in);
  EXPECT_EQ(orthogonal.status, IolStatus::singular);
  EXPECT_NEAR(orthogonal.det_B, 0.0, 1e-12);
  EXPECT_EQ(orthogonal.i_next_AB_A, in.i_s_AB_A);
  for (const Vec2<double>& flux : {Vec2<double>(0.0, 0.0), Vec2<double>(std::nan(""), 0.0)}) {
    in.flux_s_AB_Wb = flux;
    const IolOutput<double> out = iol.step(in);
    EXPECT_EQ(out.status, IolStatus::singular);
    EXPECT_EQ(out.i_next_AB_A, in.i_s_AB_A);
  }
}

TEST_F(IolTest, AFluxCommandThatBreaksTheGuardByItselfIsRefused) {
  // v2 <= -e F asks for a stator flux at k+1 pointing away from phi_r(k) whatever the torque:
  // no saturation of v1 can keep det B(k+1) < 0, so the law refuses (and holds the current).
  IolInput<double> in;
  in.flux_s_AB_Wb = {0.9, 0.0};
  in.i_s_AB_A = in.flux_s_AB_Wb / motor.Ls_H;  // the magnetized state at zero slip
  in.torque_ref_Nm = 50.0;
  in.y2_ref = -0.9;
  const IolOutput<double> out = iol.step(in);
  EXPECT_EQ(out.status, IolStatus::singular);
  EXPECT_EQ(out.i_next_AB_A, in.i_s_AB_A);
  // Non-finite commands are refused too, instead of returning a NaN current.
  in.y2_ref = 0.002;
  in.torque_ref_Nm = std::nan("");
  EXPECT_EQ(iol.step(in).status, IolStatus::singular);
  in.torque_ref_Nm = 50.0;
  in.y2_ref = std::numeric_limits<double>::infinity();
  EXPECT_EQ(iol.step(in).status, IolStatus::singular);
  in.y2_ref = 0.002;
  EXPECT_EQ(iol.step(in).status, IolStatus::ok);
}

TEST_F(IolTest, AnUnreachableCommandKeepsTheFluxAndGivesUpTorque) {
  // The reach around the held current, smaller than the step the full torque asks for, but
  // wide enough for the flux output's line: u is cut onto that line, at the torque nearest v1.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi),
      torque(-240.0, 240.0), flux2(0.6, 1.0), share(0.05, 0.6);
  for (int trial = 0; trial < 200; ++trial) {
    IolInput<double> in = operating_point(angle(rng), torque(rng), flux2(rng));
    const IolOutput<double> free = iol.step(in);
    ASSERT_FALSE(free.torque_limited);
    const Vec2<double> flux_only =
        iol.step({in.flux_s_AB_Wb, in.i_s_AB_A, 0.0, in.y2_ref, {}}).i_next_AB_A;
    // A disk around the flux-only command (on the line) that leaves out the full command.
    in.reach = {flux_only, share(rng) * (free.i_next_AB_A - flux_only).norm()};
    const IolOutput<double> out = iol.step(in);
    ASSERT_EQ(out.status, IolStatus::ok);
    EXPECT_TRUE(out.reach_limited);
    EXPECT_TRUE(out.torque_limited);
    // On the disk's edge (the full command is outside; the chord's end nearest it). Rounding:
    // a few ulps of the currents, |u| <= 300 A here.
    EXPECT_NEAR((out.i_next_AB_A - in.reach.center_A).norm(), in.reach.radius_A, 1e-12 * 300.0);
    // The second output is still exact: u is on its line (the tolerance of the decoupling test).
    const Vec2<double> flux_next =
        model.next_stator_flux(in.flux_s_AB_Wb, in.i_s_AB_A, out.i_next_AB_A);
    EXPECT_NEAR(iol.y2(flux_next, in.flux_s_AB_Wb), in.y2_ref, 1e-12 * std::abs(in.y2_ref));
    // The torque given up, not reversed, and the one reported is the one produced.
    EXPECT_LT(std::abs(out.torque_cmd_Nm), std::abs(in.torque_ref_Nm));
    EXPECT_GE(out.torque_cmd_Nm * in.torque_ref_Nm, 0.0);
    EXPECT_NEAR(model.torque_Nm(flux_next, out.i_next_AB_A), out.torque_cmd_Nm, 1e-12 * 240.0);
  }
}

TEST_F(IolTest, WhereTheFluxLineMissesTheReachTheNearestCurrentIsTaken) {
  IolInput<double> in = operating_point(0.3, 100.0, 0.8);
  const IolOutput<double> free = iol.step(in);
  // The flux line's normal is n = ls sigma phi_s; a disk centred 2 A off the line (along n,
  // on the held current's side) with radius 1 A cannot meet it.
  const Vec2<double> normal = in.flux_s_AB_Wb.normalized();
  const double side = normal.dot(in.i_s_AB_A - free.i_next_AB_A) >= 0.0 ? 1.0 : -1.0;
  in.reach = {free.i_next_AB_A + side * 2.0 * normal, 1.0};
  const IolOutput<double> out = iol.step(in);
  ASSERT_EQ(out.status, IolStatus::ok);
  EXPECT_TRUE(out.reach_limited);
  // The disk's point nearest the line: 1 A from the centre, towards the line along -n.
  EXPECT_NEAR((out.i_next_AB_A - (in.reach.center_A - side * normal)).norm(), 0.0, 1e-12 * 300.0);
  // An unlimited reach changes nothing: the same command to the bit.
  in.reach = {};
  EXPECT_EQ(iol.step(in).i_next_AB_A, free.i_next_AB_A);
}

}  // namespace
}  // namespace imd::control
