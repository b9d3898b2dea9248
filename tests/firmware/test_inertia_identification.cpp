// The whole commissioning on the simulated board, with the rotating step: inertia and viscous
// friction identified on motors from 0.55 kW to 37 kW with realistic sensors and inverter.
// Bound on J: the acceptance (10 %, docs/identification.md). J's error follows the torque's,
// which follows tau_r's (bounded at 5 % by the standstill steps); the other half is left to
// the encoder's and the current noise in the two rows. B: its error is J's relative error
// times B (10 % of B) plus what the coast can resolve: a friction torque at the test speed
// below 1 % of the test torque is not told from zero (on the paper motors, whose friction is
// smaller than that, the check says the identified friction is negligible, as it is).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "control/svpwm.hpp"
#include "firmware/identification/commissioning.hpp"
#include "firmware/identification/inertia_plan.hpp"
#include "firmware/stages/sense.hpp"
#include "hal_sim/sim_board.hpp"
#include "identification_cases.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

using test_cases::Case;
using test_cases::motor_named;

template <typename T>
struct Rig final : hal::TickHandler {
  sim::SimBoard board;
  BoardSensing<T> sensing;
  Commissioning<T> commissioning;
  int32_t encoder_sign = 1;  ///< -1: an encoder wired to count against the phase sequence

  Rig(const control::MotorParameters& m, const sim::SimBoardConfig& b, const IdentificationPlan& p,
      const InertiaPlan& ip)
      : board(m, b),
        sensing(board.adc(), board.encoder(), {256, 0.5 * b.adc.full_scale_A}),
        commissioning(p, ip) {
    board.timer().start(*this);
  }
  void on_tick() noexcept override {
    const Measurement<T> m = sensing.measure(!sensing.calibrated());
    if (!m.valid) return;
    const control::Vec2<T> u =
        commissioning.step(m.i_alphabeta_A, encoder_sign * m.encoder_delta_counts);
    if (commissioning.finished()) {
      board.pwm().disable();
      return;
    }
    const auto duty = control::svpwm(u, m.v_bus_V).duty;
    board.pwm().set_duties({float(duty[0]), float(duty[1]), float(duty[2])});
    if (!board.pwm().enabled()) board.pwm().enable();
  }
};

sim::SimBoardConfig rotating_board(const Case& c) {
  return test_cases::board_for(c, 4096);
}

template <typename T>
void run(Rig<T>& rig) {
  uint64_t ticks = 0;
  while (!rig.commissioning.finished() && ticks < 3'000'000) {
    rig.board.run_tick();
    ++ticks;
  }
}

class InertiaIdentification : public ::testing::TestWithParam<Case> {};

template <typename T>
void identify_and_check(const Case& c, const char* precision) {
  const control::MotorParameters truth = motor_named(c.motor);
  const sim::SimBoardConfig b = rotating_board(c);
  Rig<T> rig(truth, b, plan_identification(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s),
             plan_inertia_test(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s, Real(b.encoder_cpr)));
  run(rig);
  ASSERT_TRUE(rig.commissioning.succeeded()) << "failure " << int(rig.commissioning.failure_code());
  const auto mechanics = rig.commissioning.mechanics();
  ASSERT_TRUE(mechanics.has_value());
  const InertiaIdentifier<T>& r = *rig.commissioning.rotating();
  const double J = double(mechanics->J_kgm2), B = double(mechanics->friction_Nms);
  const double test_speed = double(r.test_speed_rad_s()), torque = double(r.torque_Nm());
  std::printf(
      "%s (%s): J %.4g kg m^2 (true %.4g, %.2f %%), B %.3g N m s (true %.3g); test "
      "%.1f rad/s at %.3g N m; simulated s: flux up %.2f, accelerate %.2f, coast %.2f, "
      "brake %.2f, field down %.2f\n",
      c.motor, precision, J, truth.J_kgm2, 100 * std::abs(J / truth.J_kgm2 - 1), B,
      truth.friction_Nms, test_speed, torque, r.ticks_in(InertiaStep::flux_up) * 1e-4,
      r.ticks_in(InertiaStep::accelerate) * 1e-4, r.ticks_in(InertiaStep::coast) * 1e-4,
      r.ticks_in(InertiaStep::brake) * 1e-4, r.ticks_in(InertiaStep::ramp_down) * 1e-4);
  EXPECT_LT(std::abs(J / truth.J_kgm2 - 1), 0.10);
  EXPECT_LT(std::abs(B - truth.friction_Nms),
            0.10 * truth.friction_Nms + 0.01 * torque / test_speed);
  // Braked back to rest (within the 2 % of test speed the brake stops at, and what the last
  // 50 ms of field decay leave).
  EXPECT_LT(std::abs(rig.board.plant().state().omega_mech_rad_s), 0.05 * test_speed);
}

TEST_P(InertiaIdentification, IdentifiesInertiaAndFriction) {
  identify_and_check<double>(GetParam(), "double");
}

TEST_P(InertiaIdentification, InSinglePrecisionToo) {
  identify_and_check<float>(GetParam(), "float");
}

// The motors and boards of identification_cases.hpp (rotating_board: a 4096-count encoder).
INSTANTIATE_TEST_SUITE_P(Motors, InertiaIdentification,
                         ::testing::Values(test_cases::kSeed000, test_cases::kSeed001,
                                           test_cases::kSmall, test_cases::kSixPole,
                                           test_cases::kTwoPole, test_cases::kEightPole),
                         test_cases::case_name);

// A shaft that cannot turn in the test's time (here: a thousand times the inertia) is not an
// error: the electrical result stands and the mechanics are left to the record.
TEST(InertiaIdentification, AShaftThatDoesNotTurnSkipsTheStep) {
  const Case& c = test_cases::kSmall;
  control::MotorParameters heavy = motor_named(c.motor);
  heavy.J_kgm2 *= 1000.0;
  const sim::SimBoardConfig b = rotating_board(c);
  InertiaPlan ip =
      plan_inertia_test(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s, Real(b.encoder_cpr));
  ip.max_accelerate_s = 2.0;
  Rig<double> rig(heavy, b, plan_identification(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s), ip);
  run(rig);
  EXPECT_TRUE(rig.commissioning.succeeded());
  EXPECT_EQ(rig.commissioning.failure_code(), 7);  // no_motion
  EXPECT_FALSE(rig.commissioning.mechanics().has_value());
  EXPECT_GT(rig.commissioning.electrical().Rs_Ohm, 0.0);
}

// An encoder that counts against the phase sequence: the rotor turns the other way from the
// torque's; the step stops at once with the reason, the PWM off, nothing adopted.
TEST(InertiaIdentification, AnEncoderCountingBackwardsIsNamed) {
  const Case& c = test_cases::kSmall;
  const sim::SimBoardConfig b = rotating_board(c);
  Rig<float> rig(
      motor_named(c.motor), b, plan_identification(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s),
      plan_inertia_test(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s, Real(b.encoder_cpr)));
  rig.encoder_sign = -1;
  run(rig);
  EXPECT_FALSE(rig.commissioning.succeeded());
  EXPECT_EQ(rig.commissioning.failure_code(), 8);  // wrong_direction
  EXPECT_EQ(rig.commissioning.step_code(), 5);     // failed
  // Stopped early in the acceleration: the rotor never got near the test speed.
  EXPECT_LT(std::abs(rig.board.plant().state().omega_mech_rad_s),
            0.5 * double(rig.commissioning.rotating()->test_speed_rad_s()));
}

// A load that drives the shaft (an overhauling load, -1 N m against the test's 0.43 N m) from
// the start of the rotating step: the rotor runs away from the test or cannot be braked. The
// step ends with the PWM off and the reason, never under power for ever, nothing adopted.
TEST(InertiaIdentification, AShaftDrivenByItsLoadIsLeftWithThePwmOff) {
  const Case& c = test_cases::kSmall;
  const sim::SimBoardConfig b = rotating_board(c);
  Rig<float> rig(
      motor_named(c.motor), b, plan_identification(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s),
      plan_inertia_test(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s, Real(b.encoder_cpr)));
  while (!rig.commissioning.finished() && rig.commissioning.rotating() == nullptr) {
    rig.board.run_tick();  // the standstill steps, unloaded
  }
  sim::LoadProfile overhauling;
  overhauling.value_Nm = -1.0;
  rig.board.set_load_profile(overhauling);
  run(rig);
  EXPECT_TRUE(rig.commissioning.finished());
  EXPECT_FALSE(rig.commissioning.succeeded());
  const int failure = rig.commissioning.failure_code();
  EXPECT_TRUE(failure == 9 || failure == 10) << failure;  // overspeed or not_at_rest
  EXPECT_FALSE(rig.board.pwm().enabled());
}

// A nameplate with the wrong pole-pair count (1 for a six-pole motor): the field cannot be
// oriented, the speed settles far below the test speed. Named, not taken for a locked shaft or
// a heavy rotor (which would pass the commissioning with the count unverified), whatever the
// noise: the rotor creeps at a speed the block speed resolves as one or two counts, so eight
// noise realizations are run (the decision once rested on those counts and failed 3 seeds in 24).
TEST(InertiaIdentification, AWrongPolePairCountStallsAndIsNamed) {
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    Case c = test_cases::kSixPole;
    c.nameplate.pole_pairs = 1;
    sim::SimBoardConfig b = rotating_board(c);
    b.seed = seed;
    Rig<float> rig(
        motor_named(c.motor), b, plan_identification(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s),
        plan_inertia_test(c.nameplate, c.i_max_A, c.v_bus_V, b.period_s, Real(b.encoder_cpr)));
    run(rig);
    EXPECT_FALSE(rig.commissioning.succeeded()) << "seed " << seed;
    EXPECT_EQ(rig.commissioning.failure_code(), 11) << "seed " << seed;  // stalled
  }
}

}  // namespace
}  // namespace imd::firmware
