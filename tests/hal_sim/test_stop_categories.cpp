// Stop categories and the holding brake on the simulated board (docs/safety.md, "Stop
// categories"): an encoder fault at speed under an overhauling load is stopped by DC braking
// and held by the brake; a command-watchdog expiry ramps to standstill (SS1) before STO; an
// over-current is STO at once with the brake engaged in the same tick.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "firmware/drive_state.hpp"
#include "firmware/protection/stop_category.hpp"
#include "firmware/protection/trip.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/law_variant.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

using firmware::DriveState;
using firmware::StopCategory;

constexpr double kTick_s = 1e-4;

/// What a run showed of its stop, from its rows.
struct StopTrace {
  double detected_s = NAN;      ///< the first tick with a stop category
  int stop = 0;                 ///< that category
  bool line_engaged_then = false;  ///< the brake line in that tick
  double fault_state_s = NAN;   ///< the first tick in the fault state (STO)
  bool line_engaged_at_sto = false;
  double still_from_s = NAN;    ///< |w| < 1 rad/s from here to the end of the run
  double speed_at_sto_rad_s = NAN;

  void observe(const SimRow& row) {
    if (std::isnan(detected_s) && row.stop != 0) {
      detected_s = row.t_s;
      stop = row.stop;
      line_engaged_then = row.brake_line_engaged;
    }
    if (std::isnan(fault_state_s) && row.state == int(DriveState::fault)) {
      fault_state_s = row.t_s;
      line_engaged_at_sto = row.brake_line_engaged;
      speed_at_sto_rad_s = row.omega_mech_rad_s;
    }
    if (std::abs(row.omega_mech_rad_s) >= 1.0) {
      still_from_s = NAN;
    } else if (std::isnan(still_from_s)) {
      still_from_s = row.t_s;
    }
  }
};

StopTrace run(const Scenario& s) {
  StopTrace t;
  const Summary r = run_scenario(s, {[&](const SimRow& row) { t.observe(row); }, {}, {}});
  EXPECT_LE(r.faults.size(), 1u) << "one fault, one stop";
  return t;
}

/// The seed-000 realistic board at a constant speed under a constant load, a holding brake of
/// `brake_Nm` fitted.
Scenario board(double speed_rad_s, double load_Nm, double brake_Nm, double duration_s) {
  Scenario s = with_law(
      load_scenario(test::source_path("hal_sim/scenarios/seed000_realistic.toml")), "dsmc");
  s.speed = speed_steps({{0.0, speed_rad_s}});
  s.load = load_steps({{0.0, load_Nm}});
  s.max_accel_rad_s2 = 200.0;
  s.brake.holding_torque_Nm = brake_Nm;
  s.duration_s = duration_s;
  return s;
}

TEST(StopCategories, AnEncoderFaultUnderAnOverhaulingLoadIsBrakedAndHeld) {
  // 50 rad/s against 1.5 N m of gravity-like load (it drives the rotor backwards once the
  // drive lets go); the encoder freezes at 1.5 s. The brake holds 5 N m (1.5 x the motor's
  // torque at its current limit, as brakes are sized). DC braking at the current limit gives
  // up to 8.4 N m (at 24 rad/s) and lasts 0.2 s from 50 rad/s (firmware/stages/dc_brake.hpp);
  // the brake acts 30 ms after its line drops. The rotor must be still within the DC braking
  // time plus the brake's delay, and stay still to the end.
  Scenario s = board(50.0, 1.5, 5.0, 3.5);
  FaultInjection f;
  f.at_s = 1.5;
  f.kind = FaultKind::encoder_loss;
  s.faults = {f};
  const StopTrace t = run(s);
  ASSERT_FALSE(std::isnan(t.detected_s));
  EXPECT_EQ(t.stop, int(StopCategory::dc_brake));
  EXPECT_TRUE(t.line_engaged_then) << "the brake engages on the fault";
  ASSERT_FALSE(std::isnan(t.fault_state_s)) << "DC braking ends in STO";
  EXPECT_TRUE(t.line_engaged_at_sto);
  ASSERT_FALSE(std::isnan(t.still_from_s)) << "the rotor never came to rest";
  const double stop_s = t.still_from_s - t.detected_s;
  std::printf("overhauling 1.5 N m, encoder lost at 50 rad/s: detected %.4f s, |w| < 1 rad/s "
              "after %.1f ms and to the end, STO after %.1f ms of DC braking\n",
              t.detected_s, stop_s * 1e3, (t.fault_state_s - t.detected_s) * 1e3);
  EXPECT_GE(stop_s, 0.0);
  EXPECT_LT(stop_s, 0.2 + 0.03);
}

TEST(StopCategories, WithoutABrakeTheLoadRunsAwayAfterTheStop) {
  // The same fault without a brake: DC braking slows the rotor, but no braking torque holds a
  // load at standstill, and once the PWM is off the load turns the rotor backwards. This is
  // why the brake line exists; the test shows the simulation models what it is there for.
  Scenario s = board(50.0, 1.5, 0.0, 3.5);
  FaultInjection f;
  f.at_s = 1.5;
  f.kind = FaultKind::encoder_loss;
  s.faults = {f};
  const StopTrace t = run(s);
  EXPECT_EQ(t.stop, int(StopCategory::dc_brake));
  EXPECT_TRUE(std::isnan(t.still_from_s)) << "nothing holds the load";
}

TEST(StopCategories, ACommandTimeoutRampsToStandstillBeforeSto) {
  // seed000_can.toml: set_speed 50 rad/s every 50 ms until 0.8 s, then -30 rad/s; the host
  // falls silent at 0.4 s. SS1: the drive ramps from 50 rad/s at the stop deceleration
  // (200 rad/s^2: 0.25 s) to below the stop speed, keeps the brake released while it
  // controls the motion, then STO with the brake engaged.
  Scenario s = load_scenario(test::source_path("hal_sim/scenarios/seed000_can.toml"));
  s.brake.holding_torque_Nm = 5.0;
  // A clear_faults in the middle of the ramp is refused: the stop runs to its end.
  CanCommandScript clear;
  clear.index = int(s.can_commands.size());
  clear.at_s = 0.7;
  clear.message = "clear_faults";
  s.can_commands.push_back(clear);
  FaultInjection f;
  f.at_s = 0.4;
  f.kind = FaultKind::can_silence;
  s.faults = {f};
  const StopTrace t = run(s);
  EXPECT_EQ(t.stop, int(StopCategory::ss1));
  EXPECT_FALSE(t.line_engaged_then) << "released while the ramp controls the motion";
  ASSERT_FALSE(std::isnan(t.fault_state_s));
  EXPECT_TRUE(t.line_engaged_at_sto);
  const double ramp_s = t.fault_state_s - t.detected_s;
  std::printf("command timeout: SS1 from %.4f s, STO after %.1f ms at %.2f rad/s\n",
              t.detected_s, ramp_s * 1e3, t.speed_at_sto_rad_s);
  EXPECT_LT(std::abs(t.speed_at_sto_rad_s), 1.0 + 0.1);  // the stop speed, and a tick's motion
  EXPECT_GT(ramp_s, 50.0 / 200.0 - 0.01);
  EXPECT_LT(ramp_s, 50.0 / 200.0 + 0.1);  // the ramp, then the speed loop's settling
}

TEST(StopCategories, AnEncoderFaultDuringSs1EndsTheRampInSto) {
  // The SS1 ramp of a CAN silence (from 0.56 s) needs the encoder; frozen at 0.62 s, the ramp
  // cannot go on and DC braking cannot start from a stop under way: STO at once.
  Scenario s = load_scenario(test::source_path("hal_sim/scenarios/seed000_can.toml"));
  s.brake.holding_torque_Nm = 5.0;
  FaultInjection silence, encoder;
  silence.at_s = 0.4;
  silence.kind = FaultKind::can_silence;
  encoder.at_s = 0.62;
  encoder.kind = FaultKind::encoder_loss;
  s.faults = {silence, encoder};
  StopTrace t;
  run_scenario(s, {[&](const SimRow& row) { t.observe(row); }, {}, {}});
  ASSERT_FALSE(std::isnan(t.fault_state_s));
  EXPECT_LT(t.fault_state_s, 0.62 + 0.01);  // the encoder check's detection at speed, then STO
  EXPECT_TRUE(t.line_engaged_at_sto);
}

TEST(StopCategories, AnOvercurrentIsStoWithTheBrakeAtOnce) {
  Scenario s = board(50.0, 1.5, 5.0, 1.6);
  FaultInjection f;
  f.at_s = 1.5;
  f.kind = FaultKind::overcurrent;
  f.surge_A = 20.0;
  s.faults = {f};
  const StopTrace t = run(s);
  EXPECT_EQ(t.stop, int(StopCategory::sto));
  EXPECT_EQ(t.fault_state_s, t.detected_s);
  EXPECT_TRUE(t.line_engaged_then);
}

TEST(StopCategories, TheHardwareOvercurrentTripIsLatchedAndCleared) {
  // The power stage's comparator turns the outputs off on its own (TIM1's break input); the
  // drive sees it in the next tick and latches `overcurrent` with detail 3, STO, the brake on.
  // The host clears the fault at 1.7 s and enables at 1.8 s: the drive runs again.
  Scenario s = board(50.0, 0.5, 5.0, 2.5);
  for (const auto& [at_s, message] : {std::pair{1.7, "clear_faults"}, std::pair{1.8, "enable"}}) {
    CanCommandScript c;
    c.index = int(s.can_commands.size());
    c.at_s = at_s;
    c.message = message;
    s.can_commands.push_back(c);
  }
  StopTrace t;
  bool tripped = false, ran_again = false;
  const Summary r = run_scenario(
      s, {[&](const SimRow& row) {
            t.observe(row);
            if (row.t_s > 1.8 && row.state == int(DriveState::running)) ran_again = true;
          },
          {},
          {},
          [&](uint64_t, double t_s, SimBoard& b, const firmware::DriveStatus&) {
            if (!tripped && t_s >= 1.5) {
              b.pwm_side().trip();
              tripped = true;
            }
          }});
  ASSERT_EQ(r.faults.size(), 1u);
  EXPECT_EQ(r.faults.front().code, "overcurrent");
  EXPECT_EQ(r.faults.front().detail, int(firmware::kHardwareTripDetail));
  EXPECT_NEAR(r.faults.front().detected_at_s, 1.5, kTick_s / 2);
  EXPECT_EQ(t.stop, int(StopCategory::sto));
  EXPECT_TRUE(t.line_engaged_then);
  EXPECT_TRUE(ran_again) << "cleared, the trip is forgotten and the drive runs again";
}

}  // namespace
}  // namespace imd::sim
