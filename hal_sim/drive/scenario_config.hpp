#pragma once
/// What a scenario file describes, as the firmware's and the simulated board's configuration.
/// Shared by every runner of the drive against the simulated plant: drive_sim (lock-step, as
/// fast as it goes), drive_hil (real time, over SocketCAN) and the sim-tier tests.
#include <cstdint>

#include "firmware/drive_config.hpp"
#include "firmware/reference_source.hpp"
#include "hal_sim/drive/lookahead_references.hpp"
#include "hal_sim/drive/scenario_profiles.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

/// The board: period, integration, latency, sensors, bus.
SimBoardConfig board_config(const Scenario& s);

/// The scenario's load profile and initial plant state: at rest at initial_theta, magnetized
/// (Phi = Lm I, along A) if initial_flux2 > 0.
void prepare_board(SimBoard& board, const Scenario& s);

/// The drive: controller, limits, commands, and protection (defaults from the board, then the
/// scenario's [protection] table). In lock-step simulation the tick budget is checked only when
/// the scenario sets one (the host's wall-clock time per tick is not the MCU's).
firmware::DriveConfig drive_config(const Scenario& s);

/// The scenario's speed, flux and torque profiles.
ScenarioProfiles profiles(const Scenario& s);

/// The scenario's profiles as the reference source of a drive of arithmetic T: evaluated in
/// double at each tick's time, then rounded to T. The drive asks for a tick several times
/// (its look-ahead asks for k + 1 and k + 2 at tick k, and k + 3 for the next tick after the
/// PWM write): the last few ticks' references are kept, so that each profile (a sine: about 140
/// instructions) is evaluated once per tick.
template <typename T>
class ScenarioReferences final : public firmware::ReferenceSource<T> {
 public:
  explicit ScenarioReferences(const Scenario& s)
      : profiles_(profiles(s)), period_s_(s.sample_period_s) {}
  firmware::Reference<T> at_tick(uint64_t k) const noexcept override {
    Kept& kept = kept_[k % kKept];
    if (!kept.valid || kept.k != k) kept = {true, k, reference_at_tick<T>(profiles_, period_s_, k)};
    return kept.reference;
  }

 private:
  // As deep as the drive looks ahead (the current-fed law a whole T0): fewer slots would
  // evict k + 1 and k + 2 each tick to make room for the look-ahead.
  static constexpr uint64_t kKept = LookaheadReferences<T>::kDepth;
  struct Kept {
    bool valid = false;
    uint64_t k = 0;
    firmware::Reference<T> reference{};
  };
  ScenarioProfiles profiles_;
  double period_s_;
  mutable Kept kept_[kKept];  // a cache: the same values as evaluating again
};

}  // namespace imd::sim
