// The plant apart from the model ([plant], [plant] motor_file, a controller given another
// motor file than the plant's) and commissioning scenarios ([nameplate], [identify]): what
// loads, and bad input named by its key.
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
const std::string kPaper = test::source_path("hal_sim/scenarios/seed000_paper.toml");

std::string error_of(const std::string& path, const std::vector<std::string>& overrides) {
  try {
    load_scenario(path, overrides);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

std::string error_of(const std::vector<std::string>& overrides) {
  return error_of(kIdentify, overrides);
}

TEST(Scenario, ThePlantIsTheMotorUnlessPlantChangesIt) {
  const Scenario same = load_scenario(kPaper);
  EXPECT_EQ(same.plant.Rr_Ohm, same.motor.Rr_Ohm);
  EXPECT_EQ(same.plant.Lm_H, same.motor.Lm_H);
  EXPECT_EQ(same.plant.pole_pairs, same.motor.pole_pairs);
  // A cold rotor in the controller, a hot one in the simulation: only the plant changes.
  const Scenario hot = load_scenario(kPaper, {"plant.Rr_Ohm=15.15", "plant.J_kgm2=0.02"});
  EXPECT_EQ(hot.motor.Rr_Ohm, 10.1);
  EXPECT_EQ(hot.plant.Rr_Ohm, 15.15);
  EXPECT_EQ(hot.motor.J_kgm2, 0.01);
  EXPECT_EQ(hot.plant.J_kgm2, 0.02);
  EXPECT_EQ(hot.plant.Ls_H, hot.motor.Ls_H);  // the keys [plant] does not name are [motor]'s
  // A change of [motor] reaches the plant too when [plant] does not name the key.
  const Scenario both = load_scenario(kPaper, {"motor.Rs_Ohm=3.2", "plant.Rr_Ohm=5"});
  EXPECT_EQ(both.plant.Rs_Ohm, 3.2);
}

TEST(Scenario, BadPlantKeysAreRejectedWithTheirName) {
  EXPECT_NE(error_of(kPaper, {"plant.Rx_Ohm=3"}).find("unknown key plant.Rx_Ohm"),
            std::string::npos);
  EXPECT_NE(error_of(kPaper, {"plant.Rr_Ohm=-1"}).find("plant.Rr_Ohm = -1"), std::string::npos);
  EXPECT_NE(error_of(kPaper, {"plant.Lm_H=0.5"}).find("plant.Lm_H = 0.5: must satisfy"),
            std::string::npos);
  EXPECT_NE(error_of(kPaper, {"plant.pole_pairs=1.5"}).find("plant.pole_pairs = 1.5: must be an integer"),
            std::string::npos);
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
