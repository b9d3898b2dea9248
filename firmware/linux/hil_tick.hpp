#pragma once
/// One real-time period of the host-in-the-loop run: the simulated board latches its sensors,
/// the drive runs its tick, the plant integrates the period. The Linux timer calls it; the
/// plant thus advances one period per tick, in lock-step with the firmware's time base.
/// The scenario's [[faults]] are injected at their simulated times, between ticks.
#include <atomic>
#include <cmath>
#include <cstddef>
#include <vector>

#include "firmware/drive.hpp"
#include "hal/control_timer.hpp"
#include "hal_sim/drive/lockstep_period.hpp"
#include "hal_sim/fault_schedule.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::firmware {

template <typename T>
class HilTick final : public hal::TickHandler {
 public:
  /// `faults` sorted by time and already validated (fault_parameter_error): the board would
  /// skip an invalid one.
  HilTick(sim::SimBoard& board, Drive<T>& drive, std::vector<sim::FaultInjection> faults,
          const sim::ObservedRun& run)
      : board_(board),
        drive_(drive),
        faults_(std::move(faults)),
        schedule_(faults_.data(), faults_.size()),
        observer_(run) {}

  void on_tick() noexcept override {
    const double t_s = double(ticks_) * board_.config().period_s;
    schedule_.inject_due(board_, t_s, [this](const sim::FaultInjection&, bool accepted) {
      if (!accepted) ++rejected_faults_;
    });
    const sim::SimRow& row = sim::lockstep_period(board_, drive_, observer_, t_s, [this] {
      board_.begin_period();
      drive_.on_tick();
    });
    ++ticks_;
    if (!std::isfinite(row.omega_mech_rad_s)) diverged_.store(true);  // the program stops the run
  }

  bool plant_diverged() const noexcept { return diverged_.load(); }
  /// The run's rows and tracking metrics (read after the timer stopped).
  const sim::TickObserver<T>& observer() const noexcept { return observer_; }
  std::size_t faults_injected() const noexcept { return schedule_.done() - rejected_faults_; }

 private:
  sim::SimBoard& board_;
  Drive<T>& drive_;
  std::vector<sim::FaultInjection> faults_;
  sim::FaultSchedule schedule_;  ///< over faults_
  sim::TickObserver<T> observer_;
  std::size_t rejected_faults_ = 0;  ///< refused by the board (none once validated)
  uint64_t ticks_ = 0;
  std::atomic<bool> diverged_{false};
};

}  // namespace imd::firmware
