// Scenario files: the shipped ones load, overrides apply after motor_file, the events of a run
// (faults, CAN commands) and the supervision settings load, and bad input is rejected with a
// message that names the key and the value.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

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
      {{"motor.Rs_0hm=2"}, "--set motor.Rs_0hm=2: unknown key motor.Rs_0hm"},
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
      {{"inverter.i_max_A=-inf"}, "inverter.i_max_A: = -inf: must be a number > 0, or inf"},
      {{"drive.command_source=can"},
       "reference.speed: must be absent with drive.command_source = \"can\""},
      {{"drive.command_source=serial"},
       "drive.command_source: = \"serial\": must be one of \"profile\", \"can\""},
      {{"can.node_id=64"}, "can.node_id: = 64: must be in 0..63"},
      {{"can.telemetry_rate_Hz=5"}, "can.telemetry_rate_Hz: = 5: must be in 10..1000"},
      {{"protection.bus_min_V=300", "protection.bus_max_V=250"},
       "protection.bus_max_V: = 250: must be above protection.bus_min_V (300)"},
      {{"protection.adc_stuck_ticks=1"}, "protection.adc_stuck_ticks: = 1: must be in 2.."},
      {{"protection.adc_stuck_ticks=2.5"}, "protection.adc_stuck_ticks: = 2.5: must be an integer"},
      {{"protection.encoder_missing_counts=0"},
       "protection.encoder_missing_counts: = 0: must be > 0"},
      {{"protection.encoder_max_load_share=1.5"},
       "protection.encoder_max_load_share: = 1.5: must be in (0, 1)"},
      {{"protection.inverter_voltage_error_share=1"},
       "protection.inverter_voltage_error_share: = 1: must be in (0, 1)"},
      {{"protection.adc_noise_codes=0"}, "protection.adc_noise_codes: = 0: must be > 0"},
      {{"protection.overcurrent_A=0"}, "protection.overcurrent_A: = 0: must be > 0"},
      {{"protection.tick_budget_us=-5"}, "protection.tick_budget_us: = -5: must be > 0"},
      {{"protection.command_timeout_s=inf"}, "protection.command_timeout_s: = inf: must be finite"},
      {{"protection.overcurent_A=5"}, "unknown key protection.overcurent_A"},
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

/// A scenario in a scratch directory: the paper's motor, `body`, and the flux reference (with a
/// speed reference unless `with_speed` is false). Top-level keys in `body` come first.
std::string write_scenario(const std::string& name, const std::string& body,
                           bool with_speed = true) {
  const auto directory =
      std::filesystem::temp_directory_path() / ("imd_test_scenario_" + std::to_string(::getpid()));
  std::filesystem::create_directories(directory);
  const auto path = directory / (name + ".toml");
  std::ofstream file(path);
  file << "motor_file = \"" << test::source_path("hal_sim/motors/seed000.toml") << "\"\n"
       << body << "\n[reference.flux]\nflux2_Wb2 = 0.2\n";
  if (with_speed)
    file << "[reference.speed]\nkind = \"sine\"\namplitude_rad_s = 100\nfrequency_Hz = 1\n";
  return path.string();
}

TEST(Scenario, APlantThatIsNotATableIsRejected) {
  EXPECT_NE(error_of(write_scenario("plant_number", "plant = 3"), {}).find("plant must be a table"),
            std::string::npos);
}

TEST(Scenario, EventsAndSupervisionDefaultToNone) {
  const Scenario s = load_scenario(kPaper);
  EXPECT_EQ(s.command_source, "profile");
  EXPECT_EQ(s.can_node_id, 1);
  EXPECT_EQ(s.telemetry_rate_Hz, 100);
  EXPECT_TRUE(s.faults.empty());
  EXPECT_TRUE(s.can_commands.empty());
  const ProtectionSettings& p = s.protection;
  for (const auto* value :
       {&p.overcurrent_A, &p.bus_min_V, &p.bus_max_V, &p.overspeed_rad_s, &p.encoder_missing_counts,
        &p.inverter_voltage_error_share, &p.adc_noise_codes, &p.command_timeout_s, &p.tick_budget_us,
        &p.stop_decel_rad_s2}) {
    EXPECT_FALSE(value->has_value());
  }
  EXPECT_FALSE(p.adc_stuck_ticks.has_value());
  const Scenario empty = load_scenario(write_scenario("empty", "faults = []\ncan_commands = []"));
  EXPECT_TRUE(empty.faults.empty());
  EXPECT_TRUE(empty.can_commands.empty());
}

TEST(Scenario, CanAndProtectionTables) {
  const Scenario s = load_scenario(
      kPaper, {"can.node_id=5", "can.telemetry_rate_Hz=250", "protection.overcurrent_A=12",
               "protection.bus_min_V=200", "protection.bus_max_V=400",
               "protection.overspeed_rad_s=350", "protection.encoder_missing_counts=6.5",
               "protection.adc_stuck_ticks=4", "protection.inverter_voltage_error_share=0.03",
               "protection.adc_noise_codes=2.5", "protection.command_timeout_s=0.2",
               "protection.tick_budget_us=80", "protection.stop_decel_rad_s2=500"});
  EXPECT_EQ(s.can_node_id, 5);
  EXPECT_EQ(s.telemetry_rate_Hz, 250);
  const ProtectionSettings& p = s.protection;
  EXPECT_EQ(p.overcurrent_A, 12.0);
  EXPECT_EQ(p.bus_min_V, 200.0);
  EXPECT_EQ(p.bus_max_V, 400.0);
  EXPECT_EQ(p.overspeed_rad_s, 350.0);
  EXPECT_EQ(p.encoder_missing_counts, 6.5);
  EXPECT_EQ(p.adc_stuck_ticks, 4);
  EXPECT_EQ(p.inverter_voltage_error_share, 0.03);
  EXPECT_EQ(p.adc_noise_codes, 2.5);
  EXPECT_EQ(p.command_timeout_s, 0.2);
  EXPECT_EQ(p.tick_budget_us, 80.0);
  EXPECT_EQ(p.stop_decel_rad_s2, 500.0);
}

TEST(Scenario, FaultsLoadSortedByTime) {
  const Scenario s = load_scenario(write_scenario("faults", R"(
[[faults]]
at_s = 0.5
kind = "phase_loss"
phase = 2

[[faults]]
at_s = 0.2
kind = "overcurrent"
surge_A = 15.0

[[faults]]
at_s = 0.2
kind = "undervoltage"
bus_V = 200

[[faults]]
at_s = 0.3
kind = "overrun"

[[faults]]
at_s = 0.4
kind = "can_silence"
)"));
  ASSERT_EQ(s.faults.size(), 5u);
  const std::vector<FaultKind> order = {FaultKind::overcurrent, FaultKind::undervoltage,
                                        FaultKind::overrun, FaultKind::can_silence,
                                        FaultKind::phase_loss};
  for (std::size_t i = 0; i < order.size(); ++i) {
    EXPECT_EQ(s.faults[i].kind, order[i]) << i;  // by time; file order among equal times
  }
  EXPECT_EQ(s.faults[0].at_s, 0.2);
  EXPECT_EQ(s.faults[0].surge_A, 15.0);
  EXPECT_EQ(s.faults[0].phase, 0);  // default
  EXPECT_EQ(s.faults[1].bus_V, 200.0);
  EXPECT_EQ(s.faults[2].stall_us, 1000.0);  // default
  EXPECT_EQ(s.faults[4].phase, 2);
}

TEST(Scenario, CanCommandsLoadInFileOrder) {
  const Scenario s = load_scenario(write_scenario("commands", R"(
[drive]
command_source = "can"

[can]
node_id = 0

[[can_commands]]
at_s = 0.0
message = "enable"

[[can_commands]]
at_s = 0.1
message = "set_speed"
fields = { speed_ref_rad_s = 50, extra = -1.5 }
every_s = 0.05
until_s = 0.4

[[can_commands]]
at_s = 0.05
message = "set_speed"
counter = 3
corrupt_crc = true
length = 4
)",
                                                  /*with_speed=*/false));
  EXPECT_EQ(s.command_source, "can");
  EXPECT_EQ(s.can_node_id, 0);
  ASSERT_EQ(s.can_commands.size(), 3u);
  const CanCommandScript& enable = s.can_commands[0];
  EXPECT_EQ(enable.index, 0);
  EXPECT_EQ(enable.message, "enable");
  EXPECT_TRUE(enable.fields.empty());
  EXPECT_EQ(enable.every_s, 0.0);
  EXPECT_TRUE(std::isinf(enable.until_s));
  EXPECT_FALSE(enable.counter.has_value());
  EXPECT_FALSE(enable.corrupt_crc);
  EXPECT_FALSE(enable.length.has_value());
  const CanCommandScript& repeated = s.can_commands[1];
  EXPECT_EQ(repeated.index, 1);
  using Field = std::pair<std::string, double>;
  EXPECT_EQ(repeated.fields, (std::vector<Field>{{"extra", -1.5}, {"speed_ref_rad_s", 50.0}}));
  EXPECT_EQ(repeated.every_s, 0.05);
  EXPECT_EQ(repeated.until_s, 0.4);
  const CanCommandScript& bad = s.can_commands[2];
  EXPECT_EQ(bad.index, 2);
  EXPECT_EQ(bad.at_s, 0.05);
  EXPECT_EQ(bad.counter, 3);
  EXPECT_TRUE(bad.corrupt_crc);
  EXPECT_EQ(bad.length, 4);
}

TEST(Scenario, BadEventsNameTheEntryKeyAndValue) {
  struct Case {
    std::string body;
    std::string message;
    bool with_speed = true;
  };
  const std::string fault = "[[faults]]\nat_s = 0.1\n";
  const std::string command = "[[can_commands]]\nat_s = 0.1\nmessage = \"set_speed\"\n";
  const Case cases[] = {
      {fault + "kind = \"meltdown\"",
       "faults[0].kind: = \"meltdown\": must be one of \"overcurrent\", \"overvoltage\""},
      {fault, "faults[0].kind: missing key"},
      {"[[faults]]\nkind = \"adc_stuck\"", "faults[0].at_s: missing key"},
      {"[[faults]]\nat_s = -0.1\nkind = \"adc_stuck\"", "faults[0].at_s: = -0.1: must be >= 0"},
      {fault + "kind = \"overcurrent\"", "faults[0].surge_A: missing key"},
      {fault + "kind = \"overcurrent\"\nsurge_A = 0", "faults[0].surge_A: = 0: must be > 0"},
      {fault + "kind = \"phase_loss\"\nsurge_A = 5",
       "faults[0].surge_A: = 5: not a key of kind \"phase_loss\" (only of overcurrent)"},
      {fault + "kind = \"overrun\"\nphase = 1",
       "faults[0].phase: = 1: not a key of kind \"overrun\" (only of overcurrent and phase_loss)"},
      {fault + "kind = \"encoder_loss\"\nbus_V = 400.0",
       "faults[0].bus_V: = 400.0: not a key of kind \"encoder_loss\""},
      {fault + "kind = \"overcurrent\"\nsurge_A = 5\nstall_us = 10",
       "faults[0].stall_us: = 10: not a key of kind \"overcurrent\" (only of overrun)"},
      {fault + "kind = \"phase_loss\"\nphase = 3", "faults[0].phase: = 3: must be in 0..2"},
      {fault + "kind = \"overvoltage\"", "faults[0].bus_V: missing key"},
      {fault + "kind = \"overvoltage\"\nbus_V = 300",
       "faults[0].bus_V: = 300: must be above inverter.v_bus_V (311 V) for overvoltage"},
      {fault + "kind = \"undervoltage\"\nbus_V = 350",
       "faults[0].bus_V: = 350: must be below inverter.v_bus_V (311 V) for undervoltage"},
      {fault + "kind = \"overrun\"\nstall_us = 0", "faults[0].stall_us: = 0: must be > 0"},
      {fault + "kind = \"overrun\"\nstall_us = 1e9",
       "faults[0].stall_us: = 1000000000: must be below 1e9 us"},
      {fault + "kind = \"overcurrent\"\nsurge_a = 5", "unknown key faults[0].surge_a"},
      {fault + "kind = \"adc_stuck\"\n[[faults]]\nat_s = 0.2\nkind = \"adc_stuk\"",
       "faults[1].kind: = \"adc_stuk\": must be one of"},
      {"faults = 3", "faults: must be an array of tables ([[faults]])"},
      {"faults = [0.1, 0.2]", "faults: must be an array of tables ([[faults]])"},
      {"[[can_commands]]\nat_s = 0.1", "can_commands[0].message: missing key"},
      {"[[can_commands]]\nat_s = 0.1\nmessage = 7",
       "can_commands[0].message: = 7: must be a string"},
      {"[[can_commands]]\nmessage = \"enable\"", "can_commands[0].at_s: missing key"},
      {command + "fields = 3", "can_commands[0].fields: = 3: must be a table of name = number"},
      {command + "fields = { speed_ref_rad_s = \"fast\" }",
       "can_commands[0].fields.speed_ref_rad_s: = \"fast\": must be a number"},
      {command + "fields = { speed_ref_rad_s = nan }",
       "can_commands[0].fields.speed_ref_rad_s: = nan: must be finite"},
      {command + "every_s = 0", "can_commands[0].every_s: = 0: must be > 0"},
      {command + "until_s = 1", "can_commands[0].until_s: = 1: ends a repeat, needs every_s"},
      {command + "every_s = 0.1\nuntil_s = 0.05",
       "can_commands[0].until_s: = 0.05: must be >= at_s (0.1)"},
      {command + "counter = 16", "can_commands[0].counter: = 16: must be in 0..15"},
      {command + "length = 9", "can_commands[0].length: = 9: must be in 0..8"},
      {command + "corrupt_crc = 1", "can_commands[0].corrupt_crc: must be true or false"},
      {command + "repeat_s = 1", "unknown key can_commands[0].repeat_s"},
      {"[drive]\ncommand_source = \"can\"",
       "reference.speed: must be absent with drive.command_source = \"can\""},
  };
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    const std::string message =
        error_of(write_scenario("bad_" + std::to_string(i), c.body, c.with_speed), {});
    EXPECT_NE(message.find(c.message), std::string::npos)
        << "case " << i << "\nwant: " << c.message << "\ngot:  " << message;
  }
}

TEST(Scenario, StepProfilesHoldAtMostKMaxSteps) {
  static_assert(LoadProfile::kMaxSteps == SpeedProfile::kMaxSteps);
  constexpr std::size_t kMax = SpeedProfile::kMaxSteps;
  const auto steps = [](const std::string& table, const std::string& values_key, std::size_t n) {
    std::string list;
    for (std::size_t i = 0; i < n; ++i) list += (i == 0 ? "" : ", ") + std::to_string(i);
    return "[" + table + "]\nkind = \"steps\"\ntimes_s = [" + list + "]\n" + values_key + " = [" +
           list + "]\n";
  };
  // At capacity: every step is kept.
  const Scenario full = load_scenario(write_scenario(
      "steps_full",
      steps("reference.speed", "values_rad_s", kMax) + steps("load", "values_Nm", kMax), false));
  EXPECT_EQ(full.speed.step_count, kMax);
  EXPECT_EQ(full.speed.at(-0.5), 0.0);
  EXPECT_EQ(full.speed.at(5.5), 5.0);
  EXPECT_EQ(full.speed.at(1e3), double(kMax - 1));
  EXPECT_EQ(full.load.step_count, kMax);
  EXPECT_EQ(full.load.at(1e3), double(kMax - 1));
  // One more: the loader names the key.
  const std::string speed_error = error_of(
      write_scenario("steps_speed_over", steps("reference.speed", "values_rad_s", kMax + 1), false),
      {});
  EXPECT_NE(speed_error.find("reference.speed.times_s: has 33 entries: must have at most 32"),
            std::string::npos)
      << speed_error;
  const std::string load_error =
      error_of(write_scenario("steps_load_over", steps("load", "values_Nm", kMax + 1)), {});
  EXPECT_NE(load_error.find("load.times_s: has 33 entries: must have at most 32"),
            std::string::npos)
      << load_error;
}

}  // namespace
}  // namespace imd::sim
