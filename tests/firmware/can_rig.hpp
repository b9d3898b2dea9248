#pragma once
// A drive on the simulated board, commanded over CAN by a host encoder: the rig of the command
// tests of every firmware image (test_drive_commands, test_run_image).
#include <vector>

#include "firmware/drive.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace imd::firmware {

/// The paper-000 motor on a realistic board, commanded over CAN as node 1.
struct CanRig {
  sim::SimBoard board;
  Drive<double> drive;
  protocol::CommandEncoder host{1};
  std::vector<hal::CanFrame> sent;

  static DriveConfig config() {
    DriveConfig c;
    c.commands_over_can = true;
    c.i_max_A = 6.0;
    c.protection.overcurrent_A = 9.0;
    c.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
    c.protection.command_timeout_s = 0.1;
    c.speed_reaching_pole = c.flux_reaching_pole = 0.98;
    c.max_accel_rad_s2 = 500.0;
    c.flux2_ref_Wb2 = 0.2;
    return c;
  }
  static sim::SimBoardConfig board_config() {
    sim::SimBoardConfig b;
    b.adc.noise_A = 0.01;
    return b;
  }
  explicit CanRig(const DriveConfig& c = config(), hal::Gpio* gpio = nullptr)
      : board(test::test_motors()[0].parameters, board_config()),
        drive(test::test_motors()[0].parameters, c,
              {board.pwm(), board.encoder(), board.adc(), board.timer(), &board.can(), gpio}) {
    board.timer().start(drive);
  }
  void send(const protocol::Command& c) { board.can_side().inject(host.encode(c)); }
  /// Enables the drive at `speed_rad_s` and runs until it runs (2 s at most), the speed sent
  /// every 500 ticks to feed the command watchdog (0.1 s).
  void enable_at(float speed_rad_s) {
    send({protocol::CommandKind::set_speed, speed_rad_s});
    send({protocol::CommandKind::enable});
    for (int k = 0; k < 20000 && drive.state() != DriveState::running; ++k) {
      run(1);
      if (k % 500 == 0) send({protocol::CommandKind::set_speed, speed_rad_s});
    }
  }
  /// Holds `speed_rad_s` for `ticks` (a multiple of 500), feeding the watchdog as above.
  void hold(float speed_rad_s, int ticks) {
    for (int n = 0; n < ticks / 500; ++n) {
      send({protocol::CommandKind::set_speed, speed_rad_s});
      run(500);
    }
  }
  void run(int ticks) {
    for (int k = 0; k < ticks; ++k) {
      board.run_tick();
      for (hal::CanFrame f; board.can_side().take_sent(f);) sent.push_back(f);
    }
  }
  /// The results of the command_ack frames sent so far.
  std::vector<protocol::CommandResult> acks() const {
    std::vector<protocol::CommandResult> r;
    for (const hal::CanFrame& f : sent) {
      if (f.id == protocol::can_id(1, protocol::MessageId::command_ack)) {
        r.push_back(protocol::CommandResult(protocol::get_raw(f.data, protocol::kCommandAckSignals[2])));
      }
    }
    return r;
  }
  int count(protocol::MessageId id) const {
    int n = 0;
    for (const hal::CanFrame& f : sent) n += f.id == protocol::can_id(1, id) ? 1 : 0;
    return n;
  }
};

}  // namespace imd::firmware
