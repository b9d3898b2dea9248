// Where a scenario's errors point: the file that holds the key (the scenario, a motor file it
// names, the --motor-file) or the flag that set it (--set, --duration-s), and for a rule
// between two keys where the other came from; and every integer key refuses a fraction, naming
// the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const std::string kPaper = test::source_path("hal_sim/scenarios/seed000_paper.toml");
const std::string kCan = test::source_path("hal_sim/scenarios/seed000_can.toml");
const std::string kIdentify = test::source_path("hal_sim/scenarios/identify.toml");

std::string error_of(const std::string& path, const std::vector<std::string>& overrides = {},
                     const std::optional<std::filesystem::path>& model_file = std::nullopt) {
  try {
    load_scenario(path, overrides, model_file);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

/// A scratch directory with files written into it.
class ScenarioFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = std::filesystem::temp_directory_path() /
                 ("imd_scenario_errors_" + std::to_string(::getpid()) + "_" + test->name());
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string write(const std::string& name, const std::string& text) const {
    const auto path = directory_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  /// paper 000's motor with `change` in place of the line of `key` ("" drops it).
  std::string motor(const std::string& name, const std::string& key,
                    const std::string& change) const {
    std::ifstream in(test::source_path("hal_sim/motors/seed000.toml"));
    std::string text;
    for (std::string line; std::getline(in, line);) {
      text += (line.rfind(key + " ", 0) == 0 ? change : line) + "\n";
    }
    return write(name, text);
  }
  /// A scenario naming motor file `motor_file`, with `body` after it.
  std::string scenario(const std::string& motor_file, const std::string& body = "") const {
    return write("scenario.toml",
                 "motor_file = \"" + motor_file + "\"\n" + body +
                     "\n[reference.flux]\nflux2_Wb2 = 0.2\n[reference.speed]\nkind = \"sine\"\n"
                     "amplitude_rad_s = 100\nfrequency_Hz = 1\n");
  }

  std::filesystem::path directory_;
};

TEST_F(ScenarioFiles, AnErrorInTheMotorFileNamesTheMotorFile) {
  const std::string bad = motor("bad.toml", "Rs_Ohm", "Rs_Ohm = -14.0");
  const std::string message = error_of(scenario("bad.toml"));
  EXPECT_TRUE(starts_with(message, bad + ": motor.Rs_Ohm = -14: must be > 0")) << message;
  const std::string fraction = motor("fraction.toml", "pole_pairs", "pole_pairs = 1.5");
  EXPECT_TRUE(starts_with(error_of(scenario("fraction.toml")),
                          fraction + ": motor.pole_pairs = 1.5: must be an integer"))
      << error_of(scenario("fraction.toml"));
  const std::string missing = motor("missing.toml", "Lm_H", "");
  EXPECT_TRUE(starts_with(error_of(scenario("missing.toml")), missing + ": missing key motor.Lm_H"))
      << error_of(scenario("missing.toml"));
}

TEST_F(ScenarioFiles, AnErrorInThePlantMotorFileNamesIt) {
  motor("good.toml", "Rs_Ohm", "Rs_Ohm = 14.0");
  const std::string bad = motor("bad_plant.toml", "Lm_H", "Lm_H = 0.5");
  const std::string message =
      error_of(scenario("good.toml", "[plant]\nmotor_file = \"bad_plant.toml\"\n"));
  EXPECT_TRUE(starts_with(message, bad + ": plant.Lm_H = 0.5: must satisfy")) << message;
  // A [plant] key of the scenario itself is the scenario's, over the plant's motor file.
  const std::string path =
      scenario("good.toml", "[plant]\nmotor_file = \"bad_plant.toml\"\nRr_Ohm = -1.0\n");
  motor("bad_plant.toml", "Rs_Ohm", "Rs_Ohm = 14.0");  // the plant's file is good again
  EXPECT_TRUE(starts_with(error_of(path), path + ": plant.Rr_Ohm = -1: must be > 0"))
      << error_of(path);
}

TEST_F(ScenarioFiles, AnErrorInTheScenarioNamesTheScenario) {
  motor("good.toml", "Rs_Ohm", "Rs_Ohm = 14.0");
  const std::string path = scenario("good.toml", "[can]\ntelemetry_rate_Hz = 100.5\n");
  EXPECT_TRUE(
      starts_with(error_of(path), path + ": can.telemetry_rate_Hz: = 100.5: must be an integer"))
      << error_of(path);
  const std::string plant = scenario("good.toml", "[plant]\nRr_Ohm = 0.0\n");
  EXPECT_TRUE(starts_with(error_of(plant), plant + ": plant.Rr_Ohm = 0: must be > 0"))
      << error_of(plant);
}

TEST_F(ScenarioFiles, AnErrorInTheControllersMotorFileNamesIt) {
  const std::string bad = motor("model.toml", "J_kgm2", "J_kgm2 = 0.0");
  const std::string message = error_of(kPaper, {}, bad);
  EXPECT_TRUE(starts_with(message, bad + ": motor.J_kgm2 = 0: must be > 0")) << message;
}

TEST(ScenarioErrors, AnOverrideErrorNamesTheOverride) {
  struct Case {
    std::vector<std::string> overrides;
    std::string message;  ///< the whole message's start
  };
  const Case cases[] = {
      {{"can.telemetry_rate_Hz=100.5"},
       "--set can.telemetry_rate_Hz=100.5: can.telemetry_rate_Hz: = 100.5: must be an integer"},
      {{"motor.Rs_Ohm=-2"}, "--set motor.Rs_Ohm=-2: motor.Rs_Ohm = -2: must be > 0"},
      {{"plant.Rr_Ohm=-1"}, "--set plant.Rr_Ohm=-1: plant.Rr_Ohm = -1: must be > 0"},
      {{"motor.pole_pairs=1.5"}, "--set motor.pole_pairs=1.5: motor.pole_pairs = 1.5: must be"},
      {{"simulation.foo=1"}, "--set simulation.foo=1: unknown key simulation.foo"},
      {{"plant.Rx_Ohm=3"}, "--set plant.Rx_Ohm=3: unknown key plant.Rx_Ohm"},
      {{"drive.controller=pid"}, "--set drive.controller=pid: drive.controller: = \"pid\""},
      // The last override of a key is the one named.
      {{"can.node_id=2", "can.node_id=99"}, "--set can.node_id=99: can.node_id: = 99: must be"},
      {{"drive.controller.x=1"}, "--set drive.controller.x=1: controller is not a table"},
  };
  for (const Case& c : cases) {
    const std::string message = error_of(kPaper, c.overrides);
    EXPECT_TRUE(starts_with(message, c.message)) << "got: " << message;
  }
  // A key of the file that an override made wrong is still the file's key.
  const std::string message = error_of(kPaper, {"simulation.duration_s=0.005"});
  EXPECT_TRUE(starts_with(message, kPaper + ": metrics.settle_s: = 0.01: must be below"))
      << message;
  EXPECT_TRUE(starts_with(error_of(kPaper, {"motor.Rs_Ohm=3", "motor.Lm_H=0.5"}),
                          "--set motor.Lm_H=0.5: motor.Lm_H = 0.5: must satisfy"));
}

TEST(ScenarioErrors, EveryIntegerKeyRefusesAFraction) {
  struct Case {
    const std::string& scenario;
    std::string key;
  };
  const Case cases[] = {
      {kPaper, "sensors.encoder_cpr"},     {kPaper, "sensors.adc_bits"},
      {kPaper, "simulation.substeps"},     {kPaper, "simulation.pwm_latency_ticks"},
      {kPaper, "simulation.seed"},         {kPaper, "can.node_id"},
      {kPaper, "can.telemetry_rate_Hz"},   {kPaper, "protection.adc_stuck_ticks"},
      {kPaper, "motor.pole_pairs"},        {kPaper, "plant.pole_pairs"},
      {kIdentify, "nameplate.pole_pairs"},
  };
  for (const Case& c : cases) {
    for (const char* value : {"2.5", "2.0"}) {
      const std::string assignment = c.key + "=" + value;
      const std::string message = error_of(c.scenario, {assignment});
      EXPECT_TRUE(starts_with(message, "--set " + assignment + ": ")) << message;
      EXPECT_NE(message.find(c.key), std::string::npos) << message;
      EXPECT_NE(message.find(std::string("= ") + value + ": must be an integer"), std::string::npos)
          << message;
    }
  }
}

TEST_F(ScenarioFiles, IntegerKeysOfEventsRefuseAFraction) {
  motor("good.toml", "Rs_Ohm", "Rs_Ohm = 14.0");
  struct Case {
    std::string body, message;
  };
  const Case cases[] = {
      {"[[faults]]\nat_s = 0.1\nkind = \"phase_loss\"\nphase = 1.5\n",
       "faults[0].phase: = 1.5: must be an integer"},
      {"[[can_commands]]\nat_s = 0.1\nmessage = \"enable\"\ncounter = 3.5\n",
       "can_commands[0].counter: = 3.5: must be an integer"},
      {"[[can_commands]]\nat_s = 0.1\nmessage = \"enable\"\nlength = 8.0\n",
       "can_commands[0].length: = 8.0: must be an integer"},
  };
  for (const Case& c : cases) {
    const std::string path = scenario("good.toml", c.body);
    EXPECT_TRUE(starts_with(error_of(path), path + ": " + c.message)) << error_of(path);
  }
}

std::string error_of_flags(const std::string& path,
                           const std::vector<ScenarioOverride>& overrides) {
  try {
    load_scenario_with_flags(path, overrides, std::nullopt);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(ScenarioErrors, ACrossKeyCheckNamesWhereEachValueCameFrom) {
  // The duration from --duration-s (or a --set) is named, with the way out, though the
  // failing key is the file's.
  EXPECT_EQ(error_of_flags(kPaper, {{"simulation.duration_s=0.005", "--duration-s 0.005"}}),
            kPaper +
                ": metrics.settle_s: = 0.01: must be below simulation.duration_s (0.005); "
                "simulation.duration_s comes from --duration-s 0.005: change it there, or --set "
                "metrics.settle_s=VALUE");
  EXPECT_EQ(error_of(kPaper, {"simulation.duration_s=0.005"}),
            kPaper +
                ": metrics.settle_s: = 0.01: must be below simulation.duration_s (0.005); "
                "simulation.duration_s comes from --set simulation.duration_s=0.005: change it "
                "there, or --set metrics.settle_s=VALUE");
  // The other way round: the flag's key fails, the file holds the other one.
  EXPECT_EQ(error_of(kPaper, {"metrics.settle_s=9"}),
            "--set metrics.settle_s=9: metrics.settle_s: = 9: must be below simulation.duration_s "
            "(8); simulation.duration_s comes from " +
                kPaper);
  // Both from one place: the short message.
  EXPECT_EQ(error_of(kPaper, {"simulation.duration_s=0.005", "metrics.settle_s=0.01"}),
            "--set metrics.settle_s=0.01: metrics.settle_s: = 0.01: must be below "
            "simulation.duration_s (0.005); simulation.duration_s comes from --set "
            "simulation.duration_s=0.005");
  EXPECT_EQ(error_of(kPaper, {"inverter.v_bus_V=600"}),
            "--set inverter.v_bus_V=600: inverter.v_bus_V: = 600: must be below "
            "sensors.adc_bus_full_scale_V (500); sensors.adc_bus_full_scale_V comes from " +
                kPaper);
}

TEST_F(ScenarioFiles, ACrossKeyCheckWithinOneFileNamesOnlyIt) {
  motor("good.toml", "Rs_Ohm", "Rs_Ohm = 14.0");
  const std::string path = scenario("good.toml", "[simulation]\nduration_s = 0.2\n");
  EXPECT_EQ(error_of(path),
            path + ": metrics.settle_s: = 0.5: must be below simulation.duration_s (0.2)");
}

TEST(ScenarioErrors, TablesAnOverrideAddsAreTheOverrides) {
  // [nameplate] from a --set on a scenario that is no commissioning run.
  EXPECT_TRUE(starts_with(error_of(kPaper, {"nameplate.pole_pairs=2"}),
                          "--set nameplate.pole_pairs=2: nameplate: a commissioning run "
                          "([nameplate]) needs drive.command_source = \"can\""))
      << error_of(kPaper, {"nameplate.pole_pairs=2"});
  EXPECT_NE(error_of(kPaper, {"nameplate.pole_pairs=2"})
                .find("drive.command_source comes from " + kPaper),
            std::string::npos);
  // The file's [nameplate] with a --set command source: the --set is named.
  EXPECT_TRUE(starts_with(error_of(kIdentify, {"drive.command_source=profile"}),
                          "--set drive.command_source=profile: drive.command_source: a "
                          "commissioning run"))
      << error_of(kIdentify, {"drive.command_source=profile"});
  // faults made a table by a --set: its error is the --set's.
  EXPECT_EQ(error_of(kPaper, {"faults.kind=overcurrent"}),
            "--set faults.kind=overcurrent: faults: must be an array of tables ([[faults]])");
}

TEST(ScenarioErrors, ALimitWithoutALimitSaysInfIsAccepted) {
  for (const char* value : {"infinity", "-inf", "0", "\"none\""}) {
    const std::string message = error_of(kPaper, {std::string("drive.max_accel_rad_s2=") + value});
    EXPECT_NE(message.find(": must be a number > 0, or inf for no limit"), std::string::npos)
        << message;
  }
  EXPECT_TRUE(std::isinf(load_scenario(kPaper, {"drive.max_accel_rad_s2=inf"}).max_accel_rad_s2));
  EXPECT_EQ(load_scenario(kPaper, {"inverter.i_max_A=30"}).i_max_A, 30.0);
}

TEST(ScenarioErrors, BusLimitsMustLieAroundTheNominalBus) {
  EXPECT_EQ(error_of(kPaper, {"protection.bus_max_V=100"}),
            "--set protection.bus_max_V=100: protection.bus_max_V: = 100: must be above "
            "inverter.v_bus_V (311 V), or the drive trips at once; inverter.v_bus_V comes from " +
                kPaper);
  EXPECT_EQ(error_of(kPaper, {"protection.bus_min_V=311"}),
            "--set protection.bus_min_V=311: protection.bus_min_V: = 311: must be below "
            "inverter.v_bus_V (311 V), or the drive trips at once; inverter.v_bus_V comes from " +
                kPaper);
  EXPECT_EQ(error_of(kPaper, {"inverter.v_bus_V=200", "protection.bus_min_V=250"}),
            "--set protection.bus_min_V=250: protection.bus_min_V: = 250: must be below "
            "inverter.v_bus_V (200 V), or the drive trips at once; inverter.v_bus_V comes from "
            "--set inverter.v_bus_V=200");
  const Scenario s =
      load_scenario(kPaper, {"protection.bus_min_V=250", "protection.bus_max_V=400"});
  EXPECT_EQ(s.protection.bus_max_V, 400.0);
}

TEST(ScenarioErrors, AMissingMotorFileSaysWhatItIsRelativeTo) {
  const std::string directory = std::filesystem::path(kPaper).parent_path().string();
  EXPECT_EQ(error_of(kPaper, {"plant.motor_file=nosuch.toml"}),
            "--set plant.motor_file=nosuch.toml: plant.motor_file: " + directory +
                "/nosuch.toml: cannot open file (\"nosuch.toml\" is taken relative to the "
                "scenario's directory, " +
                directory + ")");
  const std::string model = error_of(kPaper, {}, std::filesystem::path("nosuch_model.toml"));
  EXPECT_EQ(model,
            "nosuch_model.toml: cannot open file (a relative path is taken from the "
            "working directory, " +
                std::filesystem::current_path().string() + ")");
}

TEST(ScenarioErrors, WholeNumbersStillLoad) {
  const Scenario s = load_scenario(kCan, {"can.telemetry_rate_Hz=250", "sensors.adc_bits=14"});
  EXPECT_EQ(s.telemetry_rate_Hz, 250);
  EXPECT_EQ(s.adc.bits, 14);
}

}  // namespace
}  // namespace imd::sim
