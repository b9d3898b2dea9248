#pragma once
// The soak test's host (docs/safety-testing.md, "Soak"): from a seed, it drives a simulated board the
// way a careless host and a hostile plant would, for as long as asked, and checks invariants
// every tick. Each segment (0.5 to 4 s) it takes one action at random:
//   * a new speed command (within 0.8 of base speed either way) or flux command,
//   * a new load (an active load within half the torque at the current limit, either sign),
//   * a burst of invalid frames (bad CRC, wrong length, stale counter, out-of-range value,
//     unknown message),
//   * a disable, and an enable after it; an emergency stop, cleared and re-enabled,
//   * a fault of the board, while the drive runs above 10 rad/s (where every check can see it),
//     repaired after 0.3 s, then cleared and re-enabled.
// Between actions it keeps the command watchdog fed. The invariants: no non-finite value in
// the plant or the drive's record; speed and current within bounds; every injected fault
// detected within 1 s with its own code; no fault latched without a cause.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "firmware/telemetry.hpp"
#include "hal_sim/drive/tick_observer.hpp"
#include "hal_sim/fault_injection.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::soak {

struct Counts {
  uint64_t segments = 0, speed = 0, flux = 0, load = 0, invalid_frames = 0, disables = 0;
  uint64_t emergency_stops = 0, faults = 0, detected = 0, violations = 0;
  uint64_t faults_by_kind[sim::kFaultKindCount] = {};
};

class SoakHost {
 public:
  SoakHost(const sim::Scenario& s, uint64_t seed);

  /// Before each tick: the host's frames, faults and load (RunCallbacks::host).
  void before_tick(uint64_t k, double t_s, sim::SimBoard& board,
                   const firmware::DriveStatus& status);
  /// After each tick: the invariants on the plant and the record (RunCallbacks::row).
  void after_tick(const sim::SimRow& row);

  const Counts& counts() const noexcept { return counts_; }
  /// The first violations, described (at most 20 kept).
  const std::vector<std::string>& violations() const noexcept { return violations_; }

 private:
  enum class Phase { running, waiting_fault, waiting_clear, waiting_enable };
  void start_segment(double t_s, sim::SimBoard& board, const firmware::DriveStatus& status);
  void send(sim::SimBoard& board, firmware::protocol::MessageId id, float value,
            bool valid = true);
  void send_invalid(sim::SimBoard& board);
  void violation(double t_s, const std::string& what);
  static bool modulating(const firmware::DriveStatus& status) noexcept;

  sim::Scenario s_;
  std::mt19937_64 rng_;
  double base_speed_rad_s_, torque_limit_Nm_, flux2_Wb2_;
  double overcurrent_A_, overspeed_rad_s_;
  Counts counts_;
  std::vector<std::string> violations_;
  uint8_t counter_ = 0;
  double speed_ref_rad_s_ = 0.0;
  double next_segment_s_ = 0.2, next_keepalive_s_ = 0.0;
  Phase phase_ = Phase::running;
  double phase_until_s_ = 0.0;  ///< the waiting phase's deadline
  bool expecting_ = false;      ///< a fault (injected, or an emergency stop) is due
  bool surge_ = false;          ///< the fault due is an over-current surge
  sim::FaultInjection fault_;   ///< the one injected, while expecting_
  const char* expected_code_ = "";
  double repair_at_s_ = 0.0;
  bool repaired_ = true;
  double enable_at_s_ = 0.0;
  double t_s_ = 0.0;
};

}  // namespace imd::soak
