// The commissioning's acceptance on five motors (docs/identification.md): paper 000's, paper
// 001's 37 kW, a four-pole 0.75 kW, a two-pole 0.55 kW and an eight-pole 15 kW motor, each on a
// board with realistic sensors, dead time and device drop. hal_sim/scenarios/identify.toml runs the
// commissioning from the nameplate alone; the identified motor file then drives the motor's
// realistic profile on the true plant. Bounds: Rs 2 %, Ls 3 %, sigma Ls 5 %, tau_r 5 %, J 10 %; the
// speed RMS error on the identified file within 1.2 times that on the true file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/motor_file.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

struct Case {
  const char* name;
  std::vector<std::string> identify_overrides;  ///< the plant, its nameplate, the board
  const char* realistic;                        ///< the motor's realistic profile
};

double relative_error(double identified, double truth) {
  return std::abs(identified - truth) / truth;
}

class Commissioning : public ::testing::TestWithParam<Case> {};

TEST_P(Commissioning, IdentifiesTheMotorAndRunsItsProfileAsWellAsTheTrueFile) {
  const Case& c = GetParam();
  const Scenario identify =
      load_scenario(test::source_path("hal_sim/scenarios/identify.toml"), c.identify_overrides);
  const Summary commissioning = run_scenario(identify);
  ASSERT_TRUE(commissioning.commissioning.has_value());
  const CommissioningReport& report = *commissioning.commissioning;
  ASSERT_TRUE(report.identified.has_value()) << report.step << ", " << report.failure;
  EXPECT_TRUE(commissioning.faults.empty());
  const control::MotorParameters& m = *report.identified;
  const control::MotorParameters& truth = identify.plant;
  const auto sigma_Ls = [](const control::MotorParameters& p) {
    return p.Ls_H - p.Lm_H * p.Lm_H / p.Lr_H;
  };
  const double e_Rs = relative_error(m.Rs_Ohm, truth.Rs_Ohm);
  const double e_Ls = relative_error(m.Ls_H, truth.Ls_H);
  const double e_sigma = relative_error(sigma_Ls(m), sigma_Ls(truth));
  const double e_tau = relative_error(m.Lr_H / m.Rr_Ohm, truth.Lr_H / truth.Rr_Ohm);
  const double e_J = relative_error(m.J_kgm2, truth.J_kgm2);
  std::string steps;
  for (const auto& [step, seconds] : report.step_s)
    steps += " " + step + " " + std::to_string(seconds);
  std::printf(
      "%s: Rs %.2f %%, Ls %.2f %%, sigma Ls %.2f %%, tau_r %.2f %%, J %.2f %%; "
      "simulated s:%s (total %.1f)\n",
      c.name, 100 * e_Rs, 100 * e_Ls, 100 * e_sigma, 100 * e_tau, 100 * e_J, steps.c_str(),
      report.total_s);
  EXPECT_LT(e_Rs, 0.02);
  EXPECT_LT(e_Ls, 0.03);
  EXPECT_LT(e_sigma, 0.05);
  EXPECT_LT(e_tau, 0.05);
  EXPECT_LT(e_J, 0.10);

  // End to end: the realistic profile on the true plant, with the true and the identified file.
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() /
      ("imd_identified_" + std::string(c.name) + "_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << motor_file_text(m, "identified", "");
  const std::filesystem::path realistic = test::source_path(c.realistic);
  const Summary on_true = run_scenario(load_scenario(realistic));
  const Scenario with_identified = load_scenario(realistic, {}, file);
  std::filesystem::remove(file);
  EXPECT_EQ(with_identified.plant.Rr_Ohm, truth.Rr_Ohm);  // the plant stayed the true motor
  const Summary on_identified = run_scenario(with_identified);
  std::printf("%s: speed RMS %.4f rad/s on the true file, %.4f on the identified (ratio %.3f)\n",
              c.name, on_true.speed_rms_err_rad_s, on_identified.speed_rms_err_rad_s,
              on_identified.speed_rms_err_rad_s / on_true.speed_rms_err_rad_s);
  EXPECT_TRUE(on_true.faults.empty());
  EXPECT_TRUE(on_identified.faults.empty());
  EXPECT_LE(on_identified.speed_rms_err_rad_s, 1.2 * on_true.speed_rms_err_rad_s);
}

// Boards: paper 000's motor on the identify scenario's own (311 V, 6 A, 10 A ADC); the 37 kW
// on its realistic board (540 V, 150 A, 250 A ADC); the 0.75 kW, 0.55 kW and 15 kW on 540 V boards
// sized for them (as their realistic scenarios').
INSTANTIATE_TEST_SUITE_P(
    Motors, Commissioning,
    ::testing::Values(
        Case{"seed000", {}, "hal_sim/scenarios/seed000_realistic.toml"},
        Case{"seed001",
             {"plant.motor_file=\"../motors/seed001.toml\"", "nameplate.rated_voltage_V=400",
              "nameplate.rated_current_A=70", "nameplate.pole_pairs=2", "inverter.v_bus_V=540",
              "inverter.i_max_A=150", "sensors.adc_full_scale_A=250", "sensors.adc_noise_A=0.5",
              "sensors.adc_offset_A=0.5", "sensors.adc_bus_full_scale_V=1000",
              "inverter.dead_time_s=2e-6", "inverter.device_drop_V=1.5"},
             "hal_sim/scenarios/seed001_realistic.toml"},
        Case{"small_4pole_750W",
             {"plant.motor_file=\"../../tests/data/motors/small_4pole_750W.toml\"",
              "nameplate.rated_voltage_V=400", "nameplate.rated_current_A=1.9",
              "nameplate.pole_pairs=2", "inverter.v_bus_V=540", "sensors.adc_bus_full_scale_V=1000",
              "sensors.adc_offset_A=0.02"},
             "tests/data/scenarios/small_4pole_750W_realistic.toml"},
        Case{"two_pole_550W",
             {"plant.motor_file=\"../../tests/data/motors/two_pole_550W.toml\"",
              "nameplate.rated_voltage_V=400", "nameplate.rated_current_A=1.4",
              "nameplate.pole_pairs=1", "inverter.v_bus_V=540", "inverter.i_max_A=5",
              "sensors.adc_bus_full_scale_V=1000", "sensors.adc_offset_A=0.02"},
             "tests/data/scenarios/two_pole_550W_realistic.toml"},
        Case{"eight_pole_15kW",
             {"plant.motor_file=\"../../tests/data/motors/eight_pole_15kW.toml\"",
              "nameplate.rated_voltage_V=400", "nameplate.rated_current_A=32",
              "nameplate.pole_pairs=4", "inverter.v_bus_V=540", "inverter.i_max_A=80",
              "sensors.adc_full_scale_A=150", "sensors.adc_noise_A=0.15",
              "sensors.adc_offset_A=0.3", "sensors.adc_bus_full_scale_V=1000",
              "inverter.dead_time_s=2e-6", "inverter.device_drop_V=1.5"},
             "tests/data/scenarios/eight_pole_15kW_realistic.toml"}),
    [](const ::testing::TestParamInfo<Case>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace imd::sim
