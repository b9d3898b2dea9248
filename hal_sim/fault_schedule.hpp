#pragma once
/// A scenario's [[faults]] in time order, injected into the simulated board at the start of the
/// first tick at or after each fault's time: the one routine every runner uses (drive_sim and
/// the tests through the scenario runner, drive_hil's real-time loop). No heap.
#include <cstddef>

#include "hal_sim/fault_injection.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

class FaultSchedule {
 public:
  /// `faults` sorted by time (the scenario loader sorts them); they must outlive the schedule.
  FaultSchedule(const FaultInjection* faults, std::size_t count) noexcept
      : faults_(faults), count_(count) {}

  /// Injects the faults due by the tick at `t_s`, and calls `on_injected(fault, accepted)` for
  /// each: `accepted` is false for a fault the board refuses (fault_parameter_error says why).
  /// Then repairs the injected faults whose until_s has come since the last call (one that
  /// ends within the tick it began in never acts).
  template <typename OnInjected>
  void inject_due(SimBoard& board, double t_s, OnInjected&& on_injected) {
    for (; next_ < count_ && faults_[next_].at_s <= t_s + 1e-12; ++next_) {
      on_injected(faults_[next_], board.inject(faults_[next_]));
    }
    for (std::size_t i = 0; i < next_; ++i) {
      const double until_s = faults_[i].until_s;
      if (until_s > last_t_s_ + 1e-12 && until_s <= t_s + 1e-12) board.repair(faults_[i]);
    }
    last_t_s_ = t_s;
  }
  /// Faults injected (or refused) so far.
  std::size_t done() const noexcept { return next_; }

 private:
  const FaultInjection* faults_;
  std::size_t count_;
  std::size_t next_ = 0;
  double last_t_s_ = -1.0;
};

}  // namespace imd::sim
