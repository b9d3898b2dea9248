// Commissioning scenarios ([plant] motor_file, [nameplate], [identify]) and a controller given
// another motor file than the plant's: what loads, and bad input named by its key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const std::string kIdentify = test::source_path("hal_sim/scenarios/identify.toml");

std::string error_of(const std::vector<std::string>& overrides) {
  try {
    load_scenario(kIdentify, overrides);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(ScenarioCommissioning, TheNameplateBecomesCanWritesAndTheIdentifyCommand) {
  const Scenario s = load_scenario(kIdentify);
  ASSERT_TRUE(s.commissioning.has_value());
  EXPECT_EQ(s.commissioning->rated_voltage_V, 220.0);
  EXPECT_EQ(s.commissioning->pole_pairs, 1);
  EXPECT_TRUE(s.commissioning->rotate);
  EXPECT_EQ(s.plant.Rs_Ohm, 14.0);       // [plant] motor_file: paper 000's motor
  ASSERT_EQ(s.can_commands.size(), 5u);  // four nameplate writes, then identify
  EXPECT_EQ(s.can_commands[0].message, "parameter_access");
  EXPECT_EQ(s.can_commands[0].at_s, 0.1);
  EXPECT_EQ(s.can_commands[4].message, "identify");
  EXPECT_GT(s.can_commands[4].at_s, s.can_commands[3].at_s);
  EXPECT_EQ(s.can_commands[4].fields.at(0).second, 1.0);  // rotate
  const Scenario still = load_scenario(kIdentify, {"identify.rotate=false"});
  EXPECT_EQ(still.can_commands[4].fields.at(0).second, 0.0);
}

TEST(ScenarioCommissioning, ThePlantFileAndItsKeysChangeOnlyThePlant) {
  const Scenario s = load_scenario(
      kIdentify, {"plant.motor_file=\"../motors/seed001.toml\"", "plant.Rr_Ohm=0.09"});
  EXPECT_EQ(s.plant.Rs_Ohm, 0.052);
  EXPECT_EQ(s.plant.Rr_Ohm, 0.09);
}

TEST(ScenarioCommissioning, BadInputNamesTheKey) {
  EXPECT_NE(error_of({"nameplate.rated_current_A=-1"}).find("nameplate.rated_current_A"),
            std::string::npos);
  EXPECT_NE(error_of({"nameplate.pole_pairs=1.5"}).find("nameplate.pole_pairs"), std::string::npos);
  EXPECT_NE(error_of({"drive.command_source=\"profile\""}).find("command_source = \"can\""),
            std::string::npos);
  EXPECT_NE(error_of({"identify.start_s=200"}).find("identify.start_s"), std::string::npos);
  EXPECT_NE(error_of({"identify.spin=true"}).find("identify.spin"), std::string::npos);
  EXPECT_NE(error_of({"plant.motor_file=\"no_such.toml\""}).find("no_such.toml"),
            std::string::npos);
  // [identify] without [nameplate]: nothing to plan from.
  const std::string paper = test::source_path("hal_sim/scenarios/seed000_paper.toml");
  try {
    load_scenario(paper, {"identify.rotate=true"});
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("[nameplate]"), std::string::npos) << error.what();
  }
}

TEST(ScenarioCommissioning, AMotorFileForTheControllerLeavesThePlantTheScenariosMotor) {
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("imd_model_" + std::to_string(::getpid()) + ".toml");
  control::MotorParameters model = test::read_motor("hal_sim/motors/seed000.toml");
  model.Rr_Ohm = 7.0;
  std::ofstream(file) << motor_file_text(model, "a guess", "");
  const Scenario s =
      load_scenario(test::source_path("hal_sim/scenarios/seed000_realistic.toml"), {}, file);
  EXPECT_EQ(s.motor.Rr_Ohm, 7.0);
  EXPECT_EQ(s.plant.Rr_Ohm, 10.1);
  // motor.* then changes the controller's motor, plant.* the plant.
  const Scenario changed =
      load_scenario(test::source_path("hal_sim/scenarios/seed000_realistic.toml"),
                    {"motor.Rs_Ohm=20", "plant.Lm_H=0.38"}, file);
  EXPECT_EQ(changed.motor.Rs_Ohm, 20.0);
  EXPECT_EQ(changed.plant.Rs_Ohm, 14.0);
  EXPECT_EQ(changed.plant.Lm_H, 0.38);
  EXPECT_EQ(changed.motor.Rr_Ohm, 7.0);
  std::filesystem::remove(file);
  // A model file that is not a valid motor is refused with its own name.
  const std::filesystem::path bad = test::source_path("tests/data/motors/bad_negative_Rs.toml");
  try {
    load_scenario(test::source_path("hal_sim/scenarios/seed000_realistic.toml"), {}, bad);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("bad_negative_Rs.toml"), std::string::npos);
  }
}

}  // namespace
}  // namespace imd::sim
