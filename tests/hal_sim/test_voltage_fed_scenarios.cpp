// The seed-000 scenarios end to end: the firmware's tick on the simulated board, as drive_sim
// runs them. These are the acceptance checks of docs/results.md.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "control/voltage_fed_model.hpp"
#include "float_design_skip.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

Scenario scenario(const std::string& name, const std::vector<std::string>& overrides = {}) {
  return load_scenario(test::source_path("hal_sim/scenarios/" + name), overrides);
}

TEST(Seed000Paper, TrueStateAndLoadGiveDeadbeatTracking) {
  // On the exact model with ideal sensors and the analog inner feedback, the law puts speed and
  // squared flux on their references one period after each step: what is left is rounding and
  // the RK4 error of the plant (substeps = 20), far below 1e-6.
  const Summary r = run_scenario(scenario("seed000_paper.toml"));
  EXPECT_TRUE(r.faults.empty());
  EXPECT_EQ(r.running_from_s, 0.0);
  EXPECT_LE(r.speed_max_err_rad_s, 1e-6);
  EXPECT_LE(r.flux2_max_err_Wb2, 1e-6);
  std::printf("paper: speed max err %.2e rad/s, flux2 max err %.2e Wb^2 after 10 ms\n",
              r.speed_max_err_rad_s, r.flux2_max_err_Wb2);
}

TEST(Seed000Paper, SectionIvObserversConverge) {
  IMD_SKIP_IF_FLOAT_DESIGN(
      "the observer equals the exact model to 1e-9 with double coefficients only");
  // The paper's flux observer starts from zero; the drive holds the magnetizing current until
  // the estimate reaches 95 % of the reference, and ramps the speed reference (2000 rad/s^2) to
  // catch up with the sine afterwards.
  const Scenario s = scenario(
      "seed000_paper.toml",
      {"observers.section_iv=true", "drive.max_accel_rad_s2=2000", "metrics.settle_s=0.5"});
  const double a11 = control::discretize_voltage_fed(s.motor, s.sample_period_s).a11;
  std::vector<SimRow> rows;
  rows.reserve(80001);
  const Summary r = run_scenario(s, {[&](const SimRow& row) { rows.push_back(row); }, {}});
  ASSERT_TRUE(r.faults.empty());

  // Flux estimate: e_k = a11^k e_0 while the motor is held magnetized (the first 1000 ticks
  // are inside the magnetizing phase). The observer copies the exact model, so only rounding
  // separates them: 1e-9 of e_0.
  const double e0_A = rows[0].flux_A_Wb - rows[0].flux_A_est_Wb;
  const double e0_B = rows[0].flux_B_Wb - rows[0].flux_B_est_Wb;
  for (int k = 0; k <= 1000; ++k) {
    const double expected = std::pow(a11, k);
    ASSERT_NEAR(rows[k].flux_A_Wb - rows[k].flux_A_est_Wb, expected * e0_A, 1e-9 * std::abs(e0_A))
        << k;
    ASSERT_NEAR(rows[k].flux_B_Wb - rows[k].flux_B_est_Wb, expected * e0_B, 1e-9 * std::abs(e0_A))
        << k;
  }
  // Load: within 2 % of the 1 N m step, 100 ms after each step (square wave, 1 s period).
  for (double step_s = 0.5; step_s < s.duration_s; step_s += 0.5) {
    const auto k = static_cast<std::size_t>(std::lround((step_s + 0.1) / s.sample_period_s));
    EXPECT_NEAR(rows[k].load_est_Nm, rows[k].load_Nm, 0.02 * 1.0) << "step at " << step_s << " s";
  }
}

TEST(Seed000Realistic, MeetsTheTrackingAndLimitTargetsWithThePapersSpeedChannel) {
  // The paper's speed channel (the next speed set directly) with the scenario's reaching
  // poles; the default channel, through the torque, is tested in test_dsmc_torque_channel.cpp.
  const Scenario s = scenario("seed000_realistic.toml", {"drive.dsmc_speed_channel=paper"});
  bool all_finite = true;
  const Summary r = run_scenario(s, {[&](const SimRow& row) {
                                       all_finite = all_finite && std::isfinite(row.v_alpha_V) &&
                                                    std::isfinite(row.v_beta_V);
                                     },
                                     {}});
  EXPECT_TRUE(r.faults.empty());
  EXPECT_TRUE(all_finite);  // nothing non-finite ever reached the inverter
  // The acceptance bounds.
  EXPECT_LE(r.speed_rms_err_rad_s, 0.5);
  EXPECT_LE(r.flux2_rms_err_Wb2, 0.02 * s.flux2_Wb2);
  EXPECT_LE(r.i_peak_total_A, s.i_max_A);  // the whole run, start-up included
  // What the design achieves, with room for the noise: over ADC seeds 1-4 the speed RMS is
  // 0.067-0.079 rad/s, the flux^2 RMS 1.28-1.52e-4 Wb^2 and the saturated fraction 0.29-0.30;
  // 1.5 times the worst seed bounds them. A reaching law of the wrong sign saturates 99 % of
  // the ticks, the paper's deadbeat law 97.5 %.
  EXPECT_LE(r.speed_rms_err_rad_s, 1.5 * 0.079);
  EXPECT_LE(r.flux2_rms_err_Wb2, 1.5 * 1.52e-4);
  EXPECT_LE(r.saturated_fraction, 1.5 * 0.30);
  std::printf(
      "realistic: speed rms %.4f rad/s, flux2 rms %.3e Wb^2, i peak %.3f A, saturated %.3f\n",
      r.speed_rms_err_rad_s, r.flux2_rms_err_Wb2, r.i_peak_total_A, r.saturated_fraction);
}

TEST(Seed000Realistic, StartsFromAnyRotorAngle) {
  // The encoder observer takes its first angle from the encoder; a rotor at rest at 3.1 rad
  // must give the same performance as at 0 (0.087 against 0.079 rad/s RMS measured).
  const Summary r =
      run_scenario(scenario("seed000_realistic.toml", {"simulation.initial_theta_mech_rad=3.1"}));
  EXPECT_TRUE(r.faults.empty());
  EXPECT_LE(r.speed_rms_err_rad_s, 1.5 * 0.079);
  EXPECT_LE(r.i_peak_total_A, 6.0);
}

TEST(Seed000Paper, DigitalInnerFeedbackStaysCloseToTheAnalogLaw) {
  // Ideal sensors, no latency, a 3000 V bus so that nothing clips: what is left is running (2)
  // sampled and held. The held voltage is rotated to the middle of its period; measured
  // flux^2 RMS 1.0e-7 Wb^2 with it, 3.6e-7 without, speed RMS 8.5e-6 rad/s (analog: 2e-11).
  const Summary r = run_scenario(
      scenario("seed000_paper.toml", {"inverter.v_bus_V=3000", "sensors.adc_bus_full_scale_V=4000",
                                      "simulation.inner_feedback=digital"}));
  EXPECT_TRUE(r.faults.empty());
  EXPECT_LE(r.flux2_rms_err_Wb2, 2e-7);
  EXPECT_LE(r.speed_rms_err_rad_s, 2e-5);
}

TEST(Seed000Realistic, FloatControlStaysCloseToDouble) {
  // Float rounding changes the trajectory the way a different noise seed does; in double the
  // RMS metrics move by up to +-9 % between seeds 1..4 (docs/results.md), so 10 % is the bound
  // to meet. The single-sample maximum is not compared: it moves by +-20 % between seeds.
  const Summary d = run_scenario(scenario("seed000_realistic.toml"));
  const Summary f = run_scenario(scenario("seed000_realistic.toml", {"drive.precision=\"float\""}));
  ASSERT_TRUE(f.faults.empty());
  const auto within = [](double value, double reference) {
    return std::abs(value - reference) <= 0.1 * std::abs(reference);
  };
  EXPECT_TRUE(within(f.speed_rms_err_rad_s, d.speed_rms_err_rad_s)) << f.speed_rms_err_rad_s;
  EXPECT_TRUE(within(f.flux2_rms_err_Wb2, d.flux2_rms_err_Wb2)) << f.flux2_rms_err_Wb2;
  EXPECT_TRUE(within(f.load_est_rms_err_Nm, d.load_est_rms_err_Nm)) << f.load_est_rms_err_Nm;
  EXPECT_TRUE(within(f.i_peak_total_A, d.i_peak_total_A)) << f.i_peak_total_A;
  EXPECT_TRUE(within(f.saturated_fraction, d.saturated_fraction)) << f.saturated_fraction;
}

TEST(Seed000Realistic, TheCommandMetricLeavesOutTheRampOfASteppedReference) {
  // Two steps (0 -> 100 rad/s at 0.8 s, -> 40 rad/s at 1.8 s) behind a 200 rad/s^2 ramp. Against
  // the scenario's steps, the error is the ramp's: 100 - 200 t over 0.5 s and 60 - 200 t over
  // 0.3 s, whose squares integrate to 100^2 0.5 / 3 + 60^2 0.3 / 3, over the 2.1 s after
  // settle_s. The drive's own tracking error (about 0.1 rad/s) and the ramp's one-tick
  // discretization (0.02 rad/s) move that by under 0.5 %: 1 % tolerance.
  Scenario steps = scenario("seed000_realistic.toml");
  steps.speed.kind = SpeedProfile::Kind::steps;
  steps.speed.times_s = {0.8, 1.8};
  steps.speed.values_rad_s = {100.0, 40.0};
  steps.speed.step_count = 2;
  steps.max_accel_rad_s2 = 200.0;
  steps.duration_s = 2.6;
  const Summary r = run_scenario(steps);
  ASSERT_TRUE(r.faults.empty());
  ASSERT_LT(r.running_from_s, steps.speed.times_s[0]);
  const double ramp_rms_rad_s =
      std::sqrt((100.0 * 100.0 * 0.5 / 3 + 60.0 * 60.0 * 0.3 / 3) / (2.6 - steps.settle_s));
  EXPECT_NEAR(r.speed_rms_err_rad_s, ramp_rms_rad_s, 0.01 * ramp_rms_rad_s);
  // Against its ramped command the drive does about as well as on the shipped sine (0.086 rad/s,
  // whose 157 rad/s^2 needs no ramp): the ramp's four corners add short transients, not a
  // multiple. On the sine the two metrics are the same number: the command for each step,
  // recorded two ticks ahead, is the sine's value there.
  const Summary sine = run_scenario(scenario("seed000_realistic.toml"));
  EXPECT_NEAR(sine.speed_rms_err_cmd_rad_s, sine.speed_rms_err_rad_s,
              1e-9 * sine.speed_rms_err_rad_s);
  EXPECT_LT(r.speed_rms_err_cmd_rad_s, 2 * sine.speed_rms_err_cmd_rad_s);
  std::printf("steps behind a ramp: %.4g rad/s RMS against the steps (ramp alone %.4g), %.4g "
              "against the command; the sine: %.4g\n",
              r.speed_rms_err_rad_s, ramp_rms_rad_s, r.speed_rms_err_cmd_rad_s,
              sine.speed_rms_err_cmd_rad_s);
}

}  // namespace
}  // namespace imd::sim
