// drive_monitor send set-speed --enable against a drive on the simulated board: the enable and
// the repeated speed from one CommandRepeater start the drive and feed its 0.2 s command
// watchdog from the first tick, so it runs at the speed until the repetition ends; then the
// watchdog trips. The host loop runs in the board's simulated time.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "firmware/drive.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"
#include "tools/drive_monitor/repeat_send.hpp"

namespace imd::monitor {
namespace {

using namespace std::chrono_literals;
using firmware::DriveState;
using firmware::protocol::Command;
using firmware::protocol::CommandKind;

constexpr uint8_t kNode = 1;

firmware::DriveConfig drive_config() {
  firmware::DriveConfig c;  // the default command watchdog: 0.2 s
  c.commands_over_can = true;
  c.i_max_A = 6.0;
  c.protection.overcurrent_A = 9.0;
  c.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
  c.max_accel_rad_s2 = 500.0;
  c.flux2_ref_Wb2 = 0.2;
  return c;
}

TEST(drive_monitor_enable, OneSendStartsTheDriveAndKeepsItsWatchdogFed) {
  sim::SimBoard board(test::test_motors()[0].parameters, sim::SimBoardConfig{});
  firmware::Drive<double> drive(
      test::test_motors()[0].parameters, drive_config(),
      {board.pwm(), board.encoder(), board.adc(), board.timer(), &board.can(), nullptr});
  board.timer().start(drive);
  for (int k = 0; k < 300; ++k) board.run_tick();  // offset calibration
  ASSERT_EQ(drive.state(), DriveState::idle);

  // send --can ... --node 1 set-speed 30 --repeat-hz 10 --for-s 2 --enable, counter 0 (a fresh
  // drive accepts any first counter).
  const SteadyTime start = SteadyTime{} + 1000s;
  CommandRepeater repeater(kNode, Command{CommandKind::set_speed, 30.0f}, 0, {10.0, 2.0, 0.5},
                           start, Command{CommandKind::enable});
  bool ran = false;
  SteadyTime now = start;
  for (; !repeater.finished(now); now += 100us) {  // one tick per step
    ASSERT_LT(now, start + 10s) << "did not finish";
    while (const auto frame = repeater.frame_due(now)) {
      board.can_side().inject(*frame);
      repeater.sent(now, true);
    }
    board.run_tick();
    for (hal::CanFrame f; board.can_side().take_sent(f);) repeater.receive(now, f);
    ASSERT_NE(drive.state(), DriveState::fault) << "at " << (now - start) / 1ms << " ms";
    ran = ran || drive.state() == DriveState::running;
  }
  EXPECT_TRUE(ran);
  EXPECT_EQ(drive.state(), DriveState::running);
  EXPECT_NEAR(board.plant().state().omega_mech_rad_s, 30.0, 1.0);
  const RepeatTally& t = repeater.tally();
  EXPECT_EQ(verdict(t), RepeatVerdict::all_accepted)
      << repeat_summary(t, Command{CommandKind::set_speed, 30.0f}, 10.0);
  EXPECT_EQ(t.accepted, 20u);

  // The repetition is over: 0.2 s after the last frame the watchdog trips, as it should.
  for (int k = 0; k < 3000 && drive.state() != DriveState::fault; ++k) board.run_tick();
  EXPECT_EQ(drive.fault(), firmware::FaultCode::command_timeout);
}

}  // namespace
}  // namespace imd::monitor
