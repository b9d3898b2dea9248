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
#include "hal_sim/fault_schedule.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::firmware {

template <typename T>
class HilTick final : public hal::TickHandler {
 public:
  /// `faults` sorted by time and already validated (fault_parameter_error): the board would
  /// skip an invalid one.
  HilTick(sim::SimBoard& board, Drive<T>& drive, std::vector<sim::FaultInjection> faults)
      : board_(board),
        drive_(drive),
        faults_(std::move(faults)),
        schedule_(faults_.data(), faults_.size()) {}

  void on_tick() noexcept override {
    const double t_s = double(ticks_) * board_.config().period_s;
    schedule_.inject_due(board_, t_s, [this](const sim::FaultInjection&, bool accepted) {
      if (!accepted) ++rejected_faults_;
    });
    // The scenario runner's period (hal_sim/drive/lockstep_period.hpp) without its row and
    // metrics: in real time, on an emulated guest, every microsecond of the period counts.
    board_.begin_period();
    drive_.on_tick();
    board_.end_period();
    ++ticks_;
    const double omega = board_.plant().state().omega_mech_rad_s;
    if (!std::isfinite(omega)) diverged_.store(true);  // the program stops the run
  }

  bool plant_diverged() const noexcept { return diverged_.load(); }
  std::size_t faults_injected() const noexcept { return schedule_.done() - rejected_faults_; }

 private:
  sim::SimBoard& board_;
  Drive<T>& drive_;
  std::vector<sim::FaultInjection> faults_;
  sim::FaultSchedule schedule_;  ///< over faults_
  std::size_t rejected_faults_ = 0;  ///< refused by the board (none once validated)
  uint64_t ticks_ = 0;
  std::atomic<bool> diverged_{false};
};

}  // namespace imd::firmware
