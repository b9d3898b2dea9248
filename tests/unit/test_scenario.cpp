// Scenario files: the shipped ones load, overrides apply after motor_file, and bad input is
// rejected with a message that names the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "hal_sim/config_error.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const std::string kPaper = test::source_path("hal_sim/scenarios/seed000_paper.toml");

std::string error_of(const std::string& path, const std::vector<std::string>& overrides) {
  try {
    load_scenario(path, overrides);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(Scenario, ShippedScenariosLoad) {
  const Scenario paper = load_scenario(kPaper);
  EXPECT_EQ(paper.motor.Rs_Ohm, 14.0);  // from motor_file
  EXPECT_EQ(paper.speed.kind, SpeedProfile::Kind::sine);
  EXPECT_EQ(paper.speed.amplitude_rad_s, 100.0);
  EXPECT_EQ(paper.inner_feedback, InnerFeedback::ideal_analog);
  EXPECT_TRUE(std::isinf(paper.i_max_A));
  const Scenario realistic =
      load_scenario(test::source_path("hal_sim/scenarios/seed000_realistic.toml"));
  EXPECT_EQ(realistic.i_max_A, 6.0);
  EXPECT_EQ(realistic.encoder_cpr, 8192u);
  EXPECT_EQ(realistic.pwm_latency_ticks, 1);
}

TEST(Scenario, OverridesApplyAfterTheMotorFile) {
  const Scenario s = load_scenario(kPaper, {"motor.Rs_Ohm=3.2", "simulation.duration_s=2",
                                            "drive.precision=float", "load.high_Nm=0.5"});
  EXPECT_EQ(s.motor.Rs_Ohm, 3.2);
  EXPECT_EQ(s.duration_s, 2.0);
  EXPECT_EQ(s.precision, "float");  // a bare word is taken as a string
  EXPECT_EQ(s.load.high_Nm, 0.5);
}

TEST(Scenario, BadInputNamesTheKey) {
  struct Case {
    std::vector<std::string> overrides;
    std::string message;
  };
  const Case cases[] = {
      {{"simulation.durration_s=2"}, "unknown key simulation.durration_s"},
      {{"motor.Rs_0hm=2"}, "--set motor.Rs_0hm: unknown key"},
      {{"motor.Rs_Ohm=-2"}, "motor.Rs_Ohm = -2: must be > 0"},
      {{"simulation.duration_s=-1"}, "simulation.duration_s: = -1: must be > 0"},
      {{"drive.controller=pid"}, "drive.controller: = \"pid\": must be one of \"dsmc\""},
      {{"simulation.inner_feedback=3"}, "simulation.inner_feedback: must be one of"},
      {{"simulation.pwm_latency_ticks=2"}, "simulation.pwm_latency_ticks: = 2: must be in 0..1"},
      {{"sensors.ideal=yes"}, "sensors.ideal: must be true or false"},
      {{"drive.speed_reaching_pole=1"}, "drive.speed_reaching_pole: = 1: must be in [0, 1)"},
      {{"metrics.settle_s=9"}, "metrics.settle_s: = 9: must be below simulation.duration_s"},
      {{"reference.speed.kind=steps"}, "reference.speed.times_s: missing key"},
      {{"inverter.v_bus_V=600"},
       "inverter.v_bus_V: = 600: must be below sensors.adc_bus_full_scale_V"},
      {{"duration_s"}, "--set duration_s: expected table.key=VALUE"},
      {{"=3"}, "--set =3: expected table.key=VALUE"},
      {{"simulation.duration_s=inf"}, "simulation.duration_s: = inf: must be finite"},
      {{"load.high_Nm=nan"}, "load.high_Nm: = nan: must be finite"},
      {{"sensors.adc_bus_full_scale_V=inf"}, "sensors.adc_bus_full_scale_V: = inf: must be finite"},
      {{"drive.sample_period_s=1e-9"}, "drive.sample_period_s: = 1e-09: must be in [1e-6, 1e-2] s"},
      {{"reference.flux.flux2_Wb2=5e-4"},
       "reference.flux.flux2_Wb2: = 0.0005: must be > 0.002 Wb^2"},
      {{"sensors.ideal=false", "observers.section_iv=true"},
       "observers.section_iv: needs sensors.ideal = true"},
      {{"inverter.i_max_A=-inf"}, "inverter.i_max_A: = -inf: must be finite"},
  };
  for (const Case& c : cases) {
    const std::string message = error_of(kPaper, c.overrides);
    EXPECT_NE(message.find(c.message), std::string::npos) << "got: " << message;
  }
}

TEST(Scenario, MotorFileAndMotorTableTogetherAreRejected) {
  const auto directory =
      std::filesystem::temp_directory_path() / ("imd_test_scenario_" + std::to_string(::getpid()));
  std::filesystem::create_directories(directory);
  const auto path = directory / "both.toml";
  std::ofstream(path) << "motor_file = \"x.toml\"\n[motor]\nRs_Ohm = 1.0\n";
  EXPECT_NE(error_of(path.string(), {}).find("give either motor_file or [motor], not both"),
            std::string::npos);
  std::ofstream(path) << "motor_file = \"missing.toml\"\n";
  EXPECT_NE(error_of(path.string(), {}).find("missing.toml: cannot open file"), std::string::npos);
}

}  // namespace
}  // namespace imd::sim
