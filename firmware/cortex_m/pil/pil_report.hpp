#pragma once
/// What the processor-in-the-loop run measures and prints: the tracking errors of each tick
/// against the plant (the same metrics as drive_sim, hal_sim/run_metrics.hpp) and, at the
/// end, the summary on the console, one "pil <kind> <name> <value>" line per figure, which
/// tests/qemu/pil_test.py parses.
#include <cstdint>

#include "firmware/cortex_m/pil/recompute_probe.hpp"
#include "firmware/drive.hpp"
#include "hal_sim/drive/embedded_scenario.hpp"
#include "hal_sim/drive/stage_totals.hpp"
#include "hal_sim/drive/tick_observer.hpp"
#include "hal/cortex_m/cmsdk_uart.hpp"
#include "hal/cortex_m/two_stage_tick.hpp"
#include "hal_sim/induction_motor_plant.hpp"

namespace imd::firmware {

class PilReport {
 public:
  explicit PilReport(hal::cortex_m::CmsdkUart& console) noexcept : console_(console) {}

  /// The scenario, the law that runs it and the stack used so far.
  void start(const sim::EmbeddedScenario& s, const DriveConfig& drive,
             uint32_t counts_per_period) noexcept;
  /// A service call that rebuilt the model on the tracked rotor resistance took `counts` of
  /// the execution clock.
  void retuned(uint32_t counts) noexcept {
    ++retunes_;
    retune_counts_total_ += counts;
    if (counts > retune_counts_max_) retune_counts_max_ = counts;
  }
  /// The float discretization's recompute (recompute_probe.hpp): instructions per run and stack.
  void recompute(const RecomputeCost& cost) noexcept;
  /// The first heartbeat the drive sent after start-up: its reset cause.
  void first_heartbeat(const hal::CanFrame& frame) noexcept;
  /// The largest interval between two control stages, and the watchdog's period (counts).
  void watchdog(uint32_t interval_max_counts, uint32_t timeout_counts) noexcept;
  /// Prints each stage's mean counts per tick.
  void stages(const sim::StageTotals& totals, uint32_t clock_Hz) noexcept;
  /// Prints the summary; returns the exit status (0: no fault, no overrun, metrics measured).
  /// `whole_tick`: the control stage from its start to its end (the drive's own figure ends
  /// at the PWM write), and the tick that took longest in it.
  int finish(const Drive<float>& drive, const hal::cortex_m::TwoStageTick& timer,
             const sim::TickObserver<float>& observer, uint64_t frames_sent,
             const ExecutionStats& whole_tick, uint64_t longest_tick) noexcept;

 private:
  void metric(const char* name, double value) noexcept;

  hal::cortex_m::CmsdkUart& console_;
  uint32_t retunes_ = 0, retune_counts_max_ = 0;
  uint64_t retune_counts_total_ = 0;
};

}  // namespace imd::firmware
