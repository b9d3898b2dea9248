#pragma once
/// The processor-in-the-loop run's options, from the emulator's command line (semihosting):
/// words "scenario=NAME" (one of the compiled-in scenarios), "controller=NAME" (a law of
/// firmware/laws/law_registry.hpp, instead of the scenario's) and "plant_rr_percent=N" (the
/// plant's rotor resistance at N % of the scenario's, 10..500: a mismatch the drive's
/// rotor-resistance tracking retunes the model for), "stall_at_ms=N" and "duration_ms=N"
/// (below); other words are ignored (the
/// first is the program's name). tests/qemu/pil_test.py and tools/compare_controllers.py pass
/// them as QEMU's -semihosting-config arg=... .
#include <span>
#include <string_view>

#include "firmware/drive_config.hpp"
#include "hal_sim/drive/embedded_scenario.hpp"

namespace imd::firmware {

struct PilOptions {
  const sim::EmbeddedScenario* scenario = nullptr;  ///< the first compiled in, by default
  DriveConfig drive;                                ///< the scenario's, the law replaced
  int plant_rr_percent = 100;  ///< the plant's Rr over the scenario's, in percent
  /// "stall_at_ms=N": the control stage hangs at that simulated time (a stalled tick for the
  /// watchdog to find); -1: never. "duration_ms=N": the run's length instead of the scenario's.
  long stall_at_ms = -1, duration_ms = -1;
  const char* error = nullptr;  ///< a word that names nothing known: the run does not start
};

PilOptions parse_pil_options(std::string_view command_line,
                             std::span<const sim::EmbeddedScenario* const> scenarios) noexcept;

}  // namespace imd::firmware
