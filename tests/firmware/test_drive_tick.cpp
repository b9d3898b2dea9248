// The control tick on the simulated board: it never allocates, and a fault turns the PWM off in
// the same tick.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "firmware/drive.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// Counts every allocation of this test program while g_counting is set. GCC warns that the
// replaced delete frees what "new" returned; it is malloc's memory here, so the pair matches.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (g_counting) ++g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace imd::firmware {
namespace {

template <typename T>
struct Constant final : ReferenceSource<T> {
  Reference<T> at_tick(uint64_t k) const noexcept override {
    return {T(0.002 * double(k)), T(0.2)};
  }
};

/// Runs the drive's tick with allocation counting on.
template <typename T>
struct CountingHandler final : hal::TickHandler {
  Drive<T>& drive;
  explicit CountingHandler(Drive<T>& d) : drive(d) {}
  void on_tick() noexcept override {
    g_counting = true;
    drive.on_tick();
    g_counting = false;
  }
};

template <typename T>
void run_without_allocation() {
  sim::SimBoardConfig board_config;
  board_config.adc.noise_A = 0.01;
  sim::SimBoard board(test::test_motors()[0].parameters, board_config);
  DriveConfig config;
  config.auto_enable = true;             // no enable command on this bench
  config.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
  config.i_max_A = 6.0;
  config.protection.overcurrent_A = 9.0;
  config.speed_reaching_pole = config.flux_reaching_pole = 0.98;
  const Constant<T> references;
  Drive<T> drive(test::test_motors()[0].parameters, config,
                 {board.pwm(), board.encoder(), board.adc(), board.timer()}, {&references});
  CountingHandler<T> handler(drive);
  board.timer().start(handler);
  g_allocations = 0;
  for (int k = 0; k < 6000; ++k) board.run_tick();  // calibrate, magnetize, run
  EXPECT_EQ(drive.state(), DriveState::running);
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(DriveTick, NeverAllocatesInDouble) {
  run_without_allocation<double>();
}
TEST(DriveTick, NeverAllocatesInFloat) {
  run_without_allocation<float>();
}

TEST(DriveTick, OvercurrentTurnsThePwmOffInTheSameTick) {
  sim::SimBoard board(test::test_motors()[0].parameters, {});
  DriveConfig config;
  config.auto_enable = true;             // no enable command on this bench
  config.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
  config.i_max_A = 6.0;
  config.protection.overcurrent_A = 9.0;
  const Constant<double> references;
  Drive<double> drive(test::test_motors()[0].parameters, config,
                      {board.pwm(), board.encoder(), board.adc(), board.timer()}, {&references});
  board.timer().start(drive);
  for (int k = 0; k < 3000; ++k) board.run_tick();
  ASSERT_TRUE(board.pwm().enabled());
  sim::PlantState s = board.plant().state();
  s.i_s_alphabeta_A = {9.5, 0.0};  // phase a at 9.5 A: above the 9 A trip
  board.plant().set_state(s);
  board.run_tick();
  EXPECT_EQ(drive.state(), DriveState::fault);
  EXPECT_EQ(drive.fault(), FaultCode::overcurrent);
  EXPECT_FALSE(board.pwm().enabled());
  for (int k = 0; k < 10; ++k) board.run_tick();  // latched
  EXPECT_FALSE(board.pwm().enabled());
  EXPECT_EQ(drive.fault(), FaultCode::overcurrent);
}

/// A drive on the board, wired, with the given configuration.
struct Rig {
  sim::SimBoard board;
  Constant<double> references;
  Drive<double> drive;
  Rig(const sim::SimBoardConfig& board_config, const DriveConfig& config)
      : board(test::test_motors()[0].parameters, board_config),
        drive(test::test_motors()[0].parameters, config,
              {board.pwm(), board.encoder(), board.adc(), board.timer()}, {&references}) {
    board.timer().start(drive);
  }
};

TEST(DriveTick, BusUnderAndOvervoltageTrip) {
  for (const double bus_V : {150.0, 480.0}) {
    sim::SimBoardConfig board_config;
    board_config.v_bus_V = bus_V;
    DriveConfig config;
    config.auto_enable = true;
    config.protection.tick_budget_ns = 0;
    config.auto_enable = true;             // no enable command on this bench
    config.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
    config.protection.bus_min_V = 200.0;
    config.protection.bus_max_V = 450.0;
    Rig rig(board_config, config);
    for (int k = 0; k < 300; ++k) rig.board.run_tick();  // past the offset calibration
    EXPECT_EQ(rig.drive.fault(),
              bus_V < 200.0 ? FaultCode::bus_undervoltage : FaultCode::bus_overvoltage);
    EXPECT_FALSE(rig.board.pwm().enabled());
  }
}

TEST(DriveTick, OverrunTrips) {
  DriveConfig config;
  config.auto_enable = true;             // no enable command on this bench
  config.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
  config.protection.tick_budget_ns = 1;  // no tick runs in 1 ns
  Rig rig({}, config);
  for (int k = 0; k < 300; ++k) rig.board.run_tick();
  EXPECT_EQ(rig.drive.fault(), FaultCode::overrun);
  EXPECT_FALSE(rig.board.pwm().enabled());
  EXPECT_GE(rig.drive.execution().overruns, 1u);
}

}  // namespace
}  // namespace imd::firmware

namespace imd::firmware {
namespace {

TEST(DriveTick, OverspeedTripsOnTheEstimate) {
  // The reference climbs at 20 rad/s^2 past a 5 rad/s overspeed limit: the trip comes in the
  // tick the estimated speed crosses it, with the PWM off.
  DriveConfig config;
  config.auto_enable = true;
  config.protection.tick_budget_ns = 0;
  config.protection.overspeed_rad_s = 5.0;
  config.speed_reaching_pole = config.flux_reaching_pole = 0.98;
  Rig rig({}, config);
  double last_estimate = 0.0;
  for (int k = 0; k < 20000 && rig.drive.state() != DriveState::fault; ++k) {
    last_estimate = rig.drive.record().omega_est_rad_s;
    rig.board.run_tick();
  }
  EXPECT_EQ(rig.drive.fault(), FaultCode::overspeed);
  EXPECT_FALSE(rig.board.pwm().enabled());
  EXPECT_LE(last_estimate, 5.0);  // the tick before was within the limit
  EXPECT_GT(rig.drive.record().omega_est_rad_s, 5.0);
}

}  // namespace
}  // namespace imd::firmware
