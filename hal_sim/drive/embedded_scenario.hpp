#pragma once
/// A scenario compiled into an image that has no file system (the processor-in-the-loop run on
/// the MCU): what the scenario file gives the drive, the simulated board and the metrics,
/// already mapped (hal_sim/drive/scenario_config.hpp). tools/scenario_embed writes one from a
/// scenario file; a unit test keeps the committed ones up to date.
#include "control/motor_parameters.hpp"
#include "firmware/drive_config.hpp"
#include "hal_sim/drive/scenario_profiles.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "hal_sim/load_profile.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

struct EmbeddedScenario {
  const char* name = "";           ///< the scenario file's stem, e.g. "seed000_realistic"
  control::MotorParameters motor;  ///< the controller's
  control::MotorParameters plant;  ///< the simulated motor's
  SimBoardConfig board;
  firmware::DriveConfig drive;
  ScenarioProfiles references;
  LoadProfile load;
  PlantState initial_state;
  double duration_s = 1.0;
  double settle_s = 0.5;
};

}  // namespace imd::sim
