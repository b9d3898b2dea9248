// A scenario's mapping to the drive and the simulated board (hal_sim/drive/scenario_config):
// every law the drive registers can be named in a scenario, and [plant] reaches the board only.
#include <gtest/gtest.h>

#include <iterator>
#include <string>

#include "firmware/laws/law_registry.hpp"
#include "firmware/protocol/messages.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const std::string kRealistic = test::source_path("hal_sim/scenarios/seed000_realistic.toml");

TEST(ScenarioConfig, TheScenarioLawsAreTheDrivesLawsByTheirCanNames) {
  ASSERT_EQ(std::size(kScenarioControllers), std::size(firmware::protocol::kControllerValues));
  for (std::size_t i = 0; i < std::size(kScenarioControllers); ++i) {
    EXPECT_EQ(kScenarioControllers[i], firmware::protocol::kControllerValues[i].name);
    firmware::ControllerKind kind{};
    ASSERT_TRUE(firmware::controller_named(kScenarioControllers[i], kind));
    EXPECT_EQ(static_cast<std::size_t>(kind), i);
  }
  // A rotor-flux law loads from the realistic scenario and reaches the drive's configuration.
  const Scenario s = load_scenario(kRealistic, {"drive.controller=ifoc"});
  EXPECT_EQ(drive_config(s).controller, firmware::ControllerKind::ifoc);
}

TEST(ScenarioConfig, ThePlantReachesTheBoardAndTheMotorTheDrive) {
  const Scenario s = load_scenario(kRealistic, {"plant.Rr_Ohm=15.15", "plant.Lm_H=0.36",
                                                "simulation.initial_flux2_Wb2=0.04"});
  SimBoard board(s.plant, board_config(s));
  prepare_board(board, s);
  // The start at rest, magnetized, is the plant's steady state: i = psi / Lm of the plant.
  EXPECT_NEAR(board.plant().state().i_s_alphabeta_A.norm(), 0.2 / 0.36, 1e-12);
  EXPECT_EQ(s.motor.Rr_Ohm, 10.1);
  EXPECT_EQ(s.plant.Rr_Ohm, 15.15);
}

}  // namespace
}  // namespace imd::sim
