// The IOL inside the tick (firmware/laws/iol_stage.hpp): the current the law holds over a T0
// period when the current loop cannot deliver its command. Held at the voltage limit, the loop
// leaves the motor's current where it is; a law that kept holding its own command in its model
// asked for ever more current (over 100 A against 5 A flowing on the 37 kW motor at high speed
// in the soak), until its stator flux and phi_r turned orthogonal and it refused the state: a
// singular_control trip with no fault.
#include <gtest/gtest.h>

#include "firmware/drive_config.hpp"
#include "firmware/laws/iol_stage.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

using Vec2 = control::Vec2<double>;

class IolStageTest : public ::testing::Test {
 protected:
  control::MotorParameters motor = test::test_motors()[1].parameters;  // paper 001's 37 kW motor
  DriveConfig config = [] {
    DriveConfig c;
    c.controller = ControllerKind::iol;
    c.outer_speed_loop = c.outer_flux_loop = false;  // torque and flux references straight in
    return c;
  }();
  IolStage<double> stage{motor, config};
  const Vec2 i_magnetizing_A{20.0, 0.0};
  const Vec2 flux_r_Wb{0.8, 0.0};
  Reference<double> ref = [] {
    Reference<double> r;
    r.torque_Nm = 150.0;  // a torque step: the law asks for a new current at once
    r.stator_flux2_Wb2 = 1.0;
    return r;
  }();

  struct Period {
    IolTickResult<double> boundary;  ///< the result of its first tick
    Vec2 last_command_A;             ///< the current commanded on its last tick: u(k)
  };

  /// Runs one T0 period (its boundary first) with the current `i_flowing_A` measured, the
  /// voltage cut on the first `cut_ticks` of its ticks.
  Period period(IolStage<double>& s, const Vec2& i_flowing_A, int cut_ticks) {
    Period out;
    for (int k = 0; k < s.ticks_per_period(); ++k) {
      const IolTickResult<double> r =
          s.tick(flux_r_Wb, 100.0, ref, std::numeric_limits<double>::infinity(), i_flowing_A);
      if (k == 0) out.boundary = r;
      out.last_command_A = r.i_cmd_AB_A;
      if (k < cut_ticks) s.current_fell_short();
    }
    return out;
  }
};

TEST_F(IolStageTest, ACommandTheLoopReachesIsHeld) {
  stage.start(i_magnetizing_A);
  const Period first = period(stage, i_magnetizing_A, 0);
  ASSERT_TRUE(first.boundary.boundary);
  ASSERT_EQ(first.boundary.status, control::IolStatus::ok);
  EXPECT_EQ(first.boundary.i_held_AB_A, i_magnetizing_A);
  // The torque step asked for a new current, commanded ahead of the next boundary and held
  // over its period.
  ASSERT_NE(first.last_command_A, i_magnetizing_A);
  EXPECT_EQ(period(stage, i_magnetizing_A, 0).boundary.i_held_AB_A, first.last_command_A);
}

TEST_F(IolStageTest, ACurrentHeldAtTheVoltageLimitForAWholePeriodIsTheOneThatFlows) {
  stage.start(i_magnetizing_A);
  const Period first = period(stage, i_magnetizing_A, 0);
  // The loop is at the voltage limit for the whole next period: the current stays put.
  const Period second = period(stage, i_magnetizing_A, stage.ticks_per_period());
  ASSERT_EQ(second.boundary.i_held_AB_A, first.last_command_A);
  ASSERT_NE(second.last_command_A, i_magnetizing_A);
  EXPECT_EQ(period(stage, i_magnetizing_A, 0).boundary.i_held_AB_A, i_magnetizing_A);
}

TEST_F(IolStageTest, ACutOnPartOfAPeriodKeepsTheCommand) {
  // A cut on some ticks only is a step the loop takes in more than one tick: the command
  // arrives, and the law's model holds it, as in paper 001.
  stage.start(i_magnetizing_A);
  period(stage, i_magnetizing_A, 0);
  const Period second = period(stage, i_magnetizing_A, stage.ticks_per_period() - 1);
  ASSERT_NE(second.last_command_A, i_magnetizing_A);
  EXPECT_EQ(period(stage, i_magnetizing_A, 0).boundary.i_held_AB_A, second.last_command_A);
}

}  // namespace
}  // namespace imd::firmware
