// The commissioning as a drive mode, over CAN on the simulated board: a drive without a motor
// record is given a nameplate, identifies the motor at standstill, stores the record and runs
// on it; allowed to turn the rotor, it measures the inertia and friction too; a disable aborts
// the run; a run without a nameplate fails with its reason.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "firmware/drive.hpp"
#include "firmware/identification/inertia_plan.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "hal/storage/page_pair_store.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/sim_flash_pages.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

using protocol::Command;
using protocol::CommandKind;
using protocol::MessageId;
using protocol::ParameterOp;

const control::MotorParameters& small_motor() {
  static const control::MotorParameters m = test::test_motors()[2].parameters;  // 0.75 kW
  return m;
}

/// A 0.75 kW, 400 V motor on a 540 V board with realistic sensors, dead time and device drop.
struct IdentifyRig {
  sim::SimBoard board;
  sim::SimFlashPages pages;
  hal::PagePairStore<kMotorRecordBytes> store{pages};
  Drive<double> drive;
  protocol::CommandEncoder host{1};
  std::vector<hal::CanFrame> sent;
  double theta_start_rad = 0.0, theta_max_rad = 0.0;

  static DriveConfig config() {
    DriveConfig c;
    c.commands_over_can = true;
    c.i_max_A = 6.0;
    c.protection.overcurrent_A = 9.0;
    c.protection.bus_max_V = 700.0;
    c.protection.tick_budget_ns = 0;
    c.protection.command_timeout_s = 0.0;
    c.speed_reaching_pole = c.flux_reaching_pole = 0.98;
    c.max_accel_rad_s2 = 500.0;
    c.flux2_ref_Wb2 = 0.5;
    c.dead_time_s = 1e-6;
    return c;
  }
  static sim::SimBoardConfig board_config() {
    sim::SimBoardConfig b;
    b.v_bus_V = 540.0;
    b.adc.full_scale_A = 10.0;
    b.adc.noise_A = 0.01;
    b.adc.offset_A = {0.02, -0.02, 0.01};
    b.adc.bus_full_scale_V = 1000.0;
    b.inverter.dead_time_s = 1e-6;
    b.inverter.device_drop_V = 1.0;
    return b;
  }
  explicit IdentifyRig(const std::optional<MotorRecord>& record = std::nullopt)
      : board(small_motor(), board_config()),
        drive(record, config(),
              {board.pwm(), board.encoder(), board.adc(), board.timer(), &board.can(), nullptr,
               &store}) {
    board.timer().start(drive);
    theta_start_rad = board.plant().state().theta_mech_rad;
  }
  void send(const Command& c) { board.can_side().inject(host.encode(c)); }
  void write(MotorField f, double value) {
    send({CommandKind::parameter_access, float(value), ParameterOp::write, uint8_t(f)});
    run(3);
  }
  void nameplate() {
    write(MotorField::rated_voltage_V, 400.0);
    write(MotorField::rated_current_A, 1.9);
    write(MotorField::rated_frequency_Hz, 50.0);
    write(MotorField::pole_pairs, 2.0);
  }
  void run(int ticks) {
    for (int k = 0; k < ticks; ++k) {
      board.run_tick();
      drive.service();
      theta_max_rad =
          std::max(theta_max_rad, std::abs(board.plant().state().theta_mech_rad - theta_start_rad));
      for (hal::CanFrame f; board.can_side().take_sent(f);) sent.push_back(f);
    }
  }
  /// The last identify_progress frame: step, failure.
  std::pair<int, int> progress() const {
    std::pair<int, int> last{-1, -1};
    for (const hal::CanFrame& f : sent) {
      if (f.id == protocol::can_id(1, MessageId::identify_progress)) {
        last = {int(get_raw(f.data, protocol::kIdentifyProgressSignals[0])),
                int(get_raw(f.data, protocol::kIdentifyProgressSignals[2]))};
      }
    }
    return last;
  }
};

double relative_error(double identified, double truth) {
  return std::abs(identified - truth) / truth;
}

TEST(DriveIdentification, AnUnknownMotorIsIdentifiedStoredAndRun) {
  IdentifyRig rig;
  rig.run(300);
  ASSERT_EQ(rig.drive.state(), DriveState::unconfigured);
  rig.nameplate();
  rig.send({CommandKind::identify});
  rig.run(3);
  ASSERT_EQ(rig.drive.state(), DriveState::identifying);
  int ticks = 0;
  while (rig.drive.state() == DriveState::identifying && ticks < 200'000) {
    // A host reading the record meanwhile: reads are served during the run, and one may be in
    // flight when it ends (the result then waits for the bank).
    rig.send({CommandKind::parameter_access, 0.0f, ParameterOp::read, 0});
    rig.run(1);
    ticks += 1;
  }
  rig.run(3);  // the record applied outside the tick, the model attached
  ASSERT_EQ(rig.drive.state(), DriveState::idle)
      << "progress step " << rig.progress().first << ", failure " << rig.progress().second;
  rig.run(1000);                                    // the next 10 Hz progress frame reports the end
  EXPECT_EQ(rig.progress(), std::make_pair(4, 0));  // done, no failure
  const control::MotorParameters& truth = small_motor();
  const control::MotorParameters m = *rig.drive.motor();
  // The bounds of docs/identification.md; Lr = Ls by the equal-leakage convention, which is
  // this motor's own (its Lr equals its Ls), so Lm and Rr are checked too.
  EXPECT_LT(relative_error(m.Rs_Ohm, truth.Rs_Ohm), 0.02);
  EXPECT_LT(relative_error(m.Ls_H, truth.Ls_H), 0.03);
  EXPECT_LT(relative_error(m.Lr_H / m.Rr_Ohm, truth.Lr_H / truth.Rr_Ohm), 0.05);
  EXPECT_LT(relative_error(m.Lm_H, truth.Lm_H), 0.03);
  EXPECT_EQ(m.pole_pairs, 2);
  EXPECT_LT(rig.theta_max_rad, 2.0 * std::numbers::pi / 180.0);
  // Stored: the next power-up starts from it.
  std::array<uint8_t, kMotorRecordBytes> bytes{};
  const std::size_t n = hal::PagePairStore<kMotorRecordBytes>(rig.pages).load(bytes);
  const auto stored = decode_motor_record(std::span<const uint8_t>(bytes).first(n));
  ASSERT_TRUE(stored.has_value());
  EXPECT_EQ(stored->motor.Rs_Ohm, m.Rs_Ohm);
  EXPECT_EQ(stored->nameplate.rated_current_A, 1.9f);
  // And the drive runs the motor on it.
  rig.send({CommandKind::set_speed, 50.0f});
  rig.send({CommandKind::enable});
  rig.run(15000);
  ASSERT_EQ(rig.drive.state(), DriveState::running);
  // The DSMC holds the speed to 0.1 rad/s RMS on a known motor; 2 rad/s leaves room for what
  // the inertia placeholder (the catalogue rule, not measured) costs, and is far from the
  // 50 rad/s of a drive that does not run.
  EXPECT_NEAR(rig.board.plant().state().omega_mech_rad_s, 50.0, 2.0);
}

TEST(DriveIdentification, AllowedToTurnItMeasuresTheMechanicsToo) {
  IdentifyRig rig;
  rig.run(300);
  rig.nameplate();
  rig.send({CommandKind::identify, 1.0f});  // rotate
  rig.run(3);
  ASSERT_EQ(rig.drive.state(), DriveState::identifying);
  bool accelerated = false;  // the progress frames went through the rotating step
  for (int ticks = 0; rig.drive.state() == DriveState::identifying && ticks < 300'000;
       ticks += 100) {
    rig.run(100);
    accelerated = accelerated || rig.progress().first == 8;  // accelerate
  }
  rig.run(1003);
  ASSERT_EQ(rig.drive.state(), DriveState::idle)
      << "progress step " << rig.progress().first << ", failure " << rig.progress().second;
  EXPECT_TRUE(accelerated);
  EXPECT_EQ(rig.progress(), std::make_pair(4, 0));  // done, no failure
  const control::MotorParameters& truth = small_motor();
  const control::MotorParameters m = *rig.drive.motor();
  // The bounds of test_inertia_identification.cpp: J 10 %; B 10 % plus 1 % of the test torque
  // over the test speed, the operating point the drive planned for this nameplate and board.
  StandstillResult<double> electrical;
  electrical.Rs_Ohm = truth.Rs_Ohm;
  electrical.Ls_H = truth.Ls_H;
  electrical.Lm2_over_Lr_H = truth.Lm_H * truth.Lm_H / truth.Lr_H;
  electrical.sigma_Ls_H = truth.Ls_H - electrical.Lm2_over_Lr_H;
  electrical.tau_r_s = truth.Lr_H / truth.Rr_Ohm;
  const InertiaIdentifier<double> test_point(
      InertiaSettings<double>(plan_inertia_test({400.0, 1.9, 50.0, 2},
                                                IdentifyRig::config().i_max_A, 540.0, 1e-4,
                                                Real(rig.board.config().encoder_cpr))),
      electrical);
  EXPECT_LT(relative_error(m.J_kgm2, truth.J_kgm2), 0.10);
  EXPECT_NEAR(
      m.friction_Nms, truth.friction_Nms,
      0.1 * truth.friction_Nms + 0.01 * test_point.torque_Nm() / test_point.test_speed_rad_s());
  EXPECT_GT(rig.theta_max_rad, 2.0 * std::numbers::pi);                  // it did turn
  EXPECT_LT(std::abs(rig.board.plant().state().omega_mech_rad_s), 2.0);  // and was braked
}

// A drive already running on a record (here one with a cold rotor's resistance, half the true
// one) is commissioned from idle: its law stays out of the way while the commissioning drives
// the motor, and the result replaces the record.
TEST(DriveIdentification, ADriveWithARecordIsCommissionedFromIdle) {
  control::MotorParameters cold = small_motor();
  cold.Rr_Ohm *= 0.5;
  IdentifyRig rig{MotorRecord(cold)};
  rig.run(300);
  ASSERT_EQ(rig.drive.state(), DriveState::idle);
  rig.nameplate();
  rig.send({CommandKind::identify});
  rig.run(3);
  ASSERT_EQ(rig.drive.state(), DriveState::identifying);
  for (int ticks = 0; rig.drive.state() == DriveState::identifying && ticks < 200'000;
       ticks += 100) {
    rig.run(100);
  }
  rig.run(1003);
  ASSERT_EQ(rig.drive.state(), DriveState::idle) << "fault " << int(rig.drive.fault());
  EXPECT_EQ(rig.progress(), std::make_pair(4, 0));  // done, no failure
  const control::MotorParameters m = *rig.drive.motor();
  EXPECT_LT(relative_error(m.Lr_H / m.Rr_Ohm, small_motor().Lr_H / small_motor().Rr_Ohm), 0.05);
  EXPECT_EQ(m.J_kgm2, cold.J_kgm2);  // standstill only: the record's mechanics are kept
}

TEST(DriveIdentification, ADisableAbortsTheRunWithThePwmOff) {
  IdentifyRig rig;
  rig.run(300);
  rig.nameplate();
  rig.send({CommandKind::identify});
  rig.run(2000);
  ASSERT_EQ(rig.drive.state(), DriveState::identifying);
  EXPECT_TRUE(rig.board.pwm().enabled());
  rig.send({CommandKind::disable});
  rig.run(2000);  // a heartbeat period: the progress frame says why
  EXPECT_EQ(rig.drive.state(), DriveState::unconfigured);
  EXPECT_FALSE(rig.board.pwm().enabled());
  EXPECT_EQ(rig.progress(), std::make_pair(5, 5));  // failed, aborted
  EXPECT_FALSE(rig.drive.motor().has_value());
}

TEST(DriveIdentification, WithoutANameplateTheRunFailsAndSaysWhy) {
  IdentifyRig rig;
  rig.run(300);
  rig.write(MotorField::rated_voltage_V, 400.0);  // the rest of the nameplate is missing
  rig.send({CommandKind::identify});
  rig.run(2000);
  EXPECT_EQ(rig.drive.state(), DriveState::unconfigured);
  EXPECT_FALSE(rig.board.pwm().enabled());
  EXPECT_EQ(rig.progress(), std::make_pair(5, 4));  // failed, no_nameplate
}

}  // namespace
}  // namespace imd::firmware
