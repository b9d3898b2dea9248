// Dead-time compensation (firmware/stages/dead_time_compensation.hpp): the duty shift alone, and
// the modulate stage on a simulated board whose inverter has dead time: at standstill with a DC
// current the steady state is I = u/Rs (model (1), w = 0), so a compensated dead time leaves the
// current the ideal inverter gives.
#include <gtest/gtest.h>

#include <cmath>

#include "control/motor_parameters.hpp"
#include "firmware/paper_motor.hpp"
#include "firmware/stages/dead_time_compensation.hpp"
#include "firmware/stages/svpwm_stage.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::firmware {
namespace {

constexpr double kPeriod_s = 1e-4;
constexpr double kBus_V = 311.0;
constexpr double kDeadTime_s = 1e-6;

double sigma_H() {
  return control::derive_voltage_fed(test::paper_motor()).sigma_H;
}

TEST(DeadTimeCompensation, ShiftsEachDutyByTheDeadTimeShareAlongItsCurrent) {
  const DeadTimeCompensation<double> comp(true, kDeadTime_s, kPeriod_s, sigma_H());
  ASSERT_TRUE(comp.active());
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  comp.apply(duty, control::Vec2<double>(4.0, 0.0), kBus_V);  // i = (4, -2, -2) A, beyond the band
  EXPECT_FLOAT_EQ(duty[0], 0.5f + 0.01f);
  EXPECT_FLOAT_EQ(duty[1], 0.5f - 0.01f);
  EXPECT_FLOAT_EQ(duty[2], 0.5f - 0.01f);
}

TEST(DeadTimeCompensation, ScalesDownLinearlyWithinTheRippleBand) {
  const DeadTimeCompensation<double> comp(true, kDeadTime_s, kPeriod_s, sigma_H());
  const double band_A = kBus_V * kPeriod_s / (12.0 * sigma_H());
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  comp.apply(duty, control::Vec2<double>(0.5 * band_A, 0.0), kBus_V);  // i_a at half the band
  EXPECT_NEAR(duty[0], 0.5 + 0.5 * 0.01, 1e-7);  // float duty: 6e-8 resolution at 0.5
  EXPECT_NEAR(duty[1], 0.5 - 0.25 * 0.01, 1e-7);
}

TEST(DeadTimeCompensation, OffByItsSwitchOrWithoutDeadTime) {
  for (const auto& comp : {DeadTimeCompensation<double>(false, kDeadTime_s, kPeriod_s, 0.05),
                           DeadTimeCompensation<double>(true, 0.0, kPeriod_s, 0.05)}) {
    EXPECT_FALSE(comp.active());
    hal::PhaseDuties duty{0.5f, 0.4f, 0.6f};
    comp.apply(duty, control::Vec2<double>(4.0, 1.0), kBus_V);
    EXPECT_EQ(duty, (hal::PhaseDuties{0.5f, 0.4f, 0.6f}));
  }
}

/// The modulate stage holds u = (20 V, 0) at standstill on a board with dead time for 2 s
/// (48 rotor time constants); returns the current along alpha.
double dc_current_A(bool compensate) {
  sim::SimBoardConfig config;
  config.period_s = kPeriod_s;
  config.v_bus_V = kBus_V;
  config.inverter.dead_time_s = kDeadTime_s;
  sim::SimBoard board(test::paper_motor(), config);
  SvpwmStage<double> stage(board.pwm(), test::paper_motor(), kPeriod_s,
                           {compensate, kDeadTime_s, kPeriod_s, sigma_H()});
  LawOutput<double> law;
  law.v_AB_V = control::Vec2<double>(20.0, 0.0);
  for (int k = 0; k < 20000; ++k) {
    control::RotorFrameState<double> x;  // at rest, theta = 0: the rotor frame is alpha-beta
    x.i_s_AB_A = board.plant().state().i_s_alphabeta_A;
    stage.write(stage.modulate(law, x, kBus_V));
    board.run_tick();
  }
  return board.plant().state().i_s_alphabeta_A.x();
}

TEST(DeadTimeCompensation, TheModulateStageCancelsTheBoardsDeadTime) {
  const double Rs_Ohm = test::paper_motor().Rs_Ohm;
  const double ideal_A = 20.0 / Rs_Ohm;
  const double lost_A = 4.0 / 3.0 * kDeadTime_s / kPeriod_s * kBus_V / Rs_Ohm;  // 0.30 A
  EXPECT_NEAR(dc_current_A(false), ideal_A - lost_A, 1e-3 * lost_A);
  // Compensated, only the float duties' rounding remains: 6e-8 of 311 V over 14 Ohm.
  EXPECT_NEAR(dc_current_A(true), ideal_A, 1e-5);
}

}  // namespace
}  // namespace imd::firmware
