#pragma once
/// One period of a lock-step run of the drive on the simulated board, the same for every
/// runner: the plant's state at t_k is kept, the tick runs (`run_tick` latches the sensors and
/// runs the drive: the scenario runner and drive_hil call them directly, the processor-in-the-
/// loop image resumes its timer, whose sample interrupt latches them), the plant integrates
/// [t_k, t_k+1], and the tick's row is observed (hal_sim/drive/tick_observer.hpp). No heap.
#include "firmware/drive.hpp"
#include "hal_sim/drive/tick_observer.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

template <typename T, typename RunTick>
const SimRow& lockstep_period(SimBoard& board, const firmware::Drive<T>& drive,
                              TickObserver<T>& observer, double t_s, RunTick&& run_tick) {
  const PlantState truth = board.plant().state();  // at t_k, before the tick
  const double load_Nm = board.load_Nm();
  run_tick();
  board.end_period();
  return observer.observe(t_s, truth, load_Nm, board, drive.record());
}

}  // namespace imd::sim
