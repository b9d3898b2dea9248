// The heartbeat's brake signal: 1 only where a brake is fitted (a brake line configured) and
// its line is not driven. A drive without a brake reports none, stopped or turning.
#include <gtest/gtest.h>

#include <optional>

#include "firmware/drive.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

using protocol::CommandKind;
using protocol::MessageId;

/// Board lines: only the brake output, recorded.
class BrakeLine final : public hal::Gpio {
 public:
  static constexpr uint8_t kBrake = 0;
  bool driven = false;
  void write(uint8_t line, bool value) noexcept override {
    if (line == kBrake) driven = value;
  }
  bool read(uint8_t) const noexcept override { return true; }
};

/// The paper-000 motor on the simulated board, commanded over CAN as node 1, with or without
/// a brake line.
struct BrakeRig {
  BrakeLine gpio;
  sim::SimBoard board;
  Drive<double> drive;
  protocol::CommandEncoder host{1};
  std::optional<int64_t> first_brake;  ///< the brake signal of the first heartbeat
  std::optional<int64_t> last_brake;   ///< the brake signal of the last heartbeat

  static DriveConfig config(bool brake_fitted) {
    DriveConfig c;
    c.commands_over_can = true;
    c.i_max_A = 6.0;
    c.protection.overcurrent_A = 9.0;
    c.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
    c.protection.command_timeout_s = 0.1;
    c.max_accel_rad_s2 = 500.0;
    c.flux2_ref_Wb2 = 0.2;
    c.brake_output_line = brake_fitted ? BrakeLine::kBrake : -1;
    return c;
  }
  explicit BrakeRig(bool brake_fitted)
      : board(test::test_motors()[0].parameters, sim::SimBoardConfig{}),
        drive(test::test_motors()[0].parameters, config(brake_fitted),
              {board.pwm(), board.encoder(), board.adc(), board.timer(), &board.can(), &gpio}) {
    board.timer().start(drive);
  }
  /// Runs `ticks` ticks, repeating the speed command every 50 ms (the watchdog is 0.1 s).
  void run(int ticks, float speed_rad_s) {
    constexpr protocol::Signal kBrake = protocol::signal_of(MessageId::heartbeat, "brake");
    for (int k = 0; k < ticks; ++k) {
      if (k % 500 == 0) board.can_side().inject(host.encode({CommandKind::set_speed, speed_rad_s}));
      board.run_tick();
      for (hal::CanFrame f; board.can_side().take_sent(f);) {
        if (f.id == protocol::can_id(1, MessageId::heartbeat)) {
          last_brake = protocol::get_raw(f.data, kBrake);
          if (!first_brake) first_brake = last_brake;
        }
      }
    }
  }
  /// Enables the drive and runs it until it runs at `speed_rad_s` and a heartbeat has passed.
  void run_at(float speed_rad_s) {
    board.can_side().inject(host.encode({CommandKind::enable}));
    for (int n = 0; n < 40 && drive.state() != DriveState::running; ++n) run(500, speed_rad_s);
    ASSERT_EQ(drive.state(), DriveState::running);
    last_brake.reset();
    run(2000, speed_rad_s);  // two heartbeat periods
  }
};

// The first heartbeat is published before any tick has computed the brake signal: it carries
// the value the drive starts with.
TEST(HeartbeatBrake, TheFirstHeartbeatReportsTheBrakeAsFitted) {
  for (const bool fitted : {false, true}) {
    SCOPED_TRACE(fitted ? "brake fitted" : "no brake");
    BrakeRig rig(fitted);
    for (int n = 0; n < 20 && !rig.first_brake; ++n) rig.run(100, 0.0f);
    ASSERT_TRUE(rig.first_brake.has_value());
    EXPECT_EQ(*rig.first_brake, fitted ? 1 : 0);
  }
}

TEST(HeartbeatBrake, ADriveWithoutABrakeReportsNoneStoppedOrTurning) {
  BrakeRig rig(false);
  rig.run(2000, 0.0f);  // calibrated, idle
  ASSERT_EQ(rig.drive.state(), DriveState::idle);
  ASSERT_TRUE(rig.last_brake.has_value());
  EXPECT_EQ(*rig.last_brake, 0);
  rig.run_at(30.0f);
  EXPECT_GT(rig.board.plant().state().omega_mech_rad_s, 20.0);  // the rotor turns
  ASSERT_TRUE(rig.last_brake.has_value());
  EXPECT_EQ(*rig.last_brake, 0);
}

TEST(HeartbeatBrake, AFittedBrakeIsEngagedUntilTheDriveRunsAndReleasedWhileItDoes) {
  BrakeRig rig(true);
  rig.run(2000, 0.0f);
  ASSERT_EQ(rig.drive.state(), DriveState::idle);
  EXPECT_FALSE(rig.gpio.driven);
  ASSERT_TRUE(rig.last_brake.has_value());
  EXPECT_EQ(*rig.last_brake, 1);
  rig.run_at(30.0f);
  EXPECT_TRUE(rig.gpio.driven);
  ASSERT_TRUE(rig.last_brake.has_value());
  EXPECT_EQ(*rig.last_brake, 0);
}

}  // namespace
}  // namespace imd::firmware
