// The processor-in-the-loop image and drive_sim measure a run with the same code: the PIL's
// loop (references filled ahead in a ring, the tick run between the board's two half-periods,
// hal_sim/drive/lockstep_period.hpp, the rows and metrics of tick_observer.hpp) gives drive_sim's
// metrics exactly, here on the current-fed law, whose stator-flux, torque and hold metrics the
// two computed differently before. (On the MCU the tick runs from SysTick in float; the qemu
// tier's pil test compares that run with the host's.)
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "hal_sim/drive/lockstep_period.hpp"
#include "hal_sim/drive/lookahead_references.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/drive/simulated_drive.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::sim {
namespace {

/// Equal, or both NaN (a metric the run does not define).
void expect_same(double pil, double drive_sim, const char* what) {
  if (std::isnan(drive_sim)) {
    EXPECT_TRUE(std::isnan(pil)) << what;
  } else {
    EXPECT_EQ(pil, drive_sim) << what;  // the same arithmetic in the same order
  }
}

TEST(LockstepAgreement, ThePilLoopGivesDriveSimsMetricsOnTheCurrentFedLaw) {
  const Scenario s =
      load_scenario(std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/seed001_realistic.toml");
  ASSERT_EQ(s.controller, "iol");
  const Summary reference = run_scenario(s);

  // The PIL image's loop, on the host.
  SimBoard board(s.motor, board_config(s));
  prepare_board(board, s);
  const ScenarioProfiles references_profile = profiles(s);
  LookaheadReferences<double> references(references_profile, s.sample_period_s);
  const firmware::DriveConfig config = drive_config(s);
  SimulatedDrive<double> simulated(board, s.motor, config,
                                   {s.ideal_sensors, s.inner_feedback, s.current_fed}, &references,
                                   board.timer(), &board.can());
  firmware::Drive<double>& drive = simulated.drive();
  TickObserver<double> observer(observed_run(references_profile, s.settle_s, s.motor, config));
  const auto ticks = static_cast<uint64_t>(std::llround(s.duration_s / s.sample_period_s));
  references.fill_from(0);
  board.timer().start(drive);  // the lock-step timer stands for the MCU's paused SysTick
  for (uint64_t k = 0; k < ticks; ++k) {
    lockstep_period(board, drive, observer, double(k) * s.sample_period_s, [&] {
      board.begin_period();
      board.fire_timer();
    });
    references.fill_from(k + 1);
    for (hal::CanFrame f; board.can_side().take_sent(f);) {
    }
  }
  ASSERT_GT(observer.metrics().measured_ticks(), 0u);
  expect_same(observer.speed_rms_err_rad_s(), reference.speed_rms_err_rad_s, "speed rms");
  expect_same(observer.metrics().flux2_rms_err_Wb2(), reference.flux2_rms_err_Wb2, "flux rms");
  expect_same(observer.metrics().flux2_max_err_Wb2(), reference.flux2_max_err_Wb2, "flux max");
  expect_same(observer.metrics().load_est_rms_err_Nm(), reference.load_est_rms_err_Nm, "load");
  expect_same(observer.metrics().i_peak_A(), reference.i_peak_A, "peak current");
  expect_same(observer.torque_rms_err_Nm(), reference.torque_rms_err_Nm, "torque rms");
  expect_same(observer.i_hold_rms_err_A(), reference.i_hold_rms_err_A, "hold rms");
  expect_same(observer.running_from_s(), reference.running_from_s, "running from");
  // The stator flux is what the current-fed law regulates: its error is measured, and small.
  EXPECT_LT(reference.flux2_rms_err_Wb2, 0.05 * s.stator_flux2_Wb2);
}

}  // namespace
}  // namespace imd::sim
