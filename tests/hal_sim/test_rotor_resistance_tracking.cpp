// Online rotor-resistance tracking end to end (docs/robustness.md): the drive on the
// simulated board with the plant's rotor hotter (1.5x) or colder (0.6x) than the motor record,
// for every law and on more than the papers' motors; a rotor heating up during a run; and the
// swap of the retuned model, which must carry every part's state over.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

struct Case {
  const char* file;  ///< under the source tree
  /// The run: long enough for the estimate to converge at the documented rate (four rotor
  /// time constants at slip tangent 1), and the metrics' window after it.
  double duration_s, settle_s;
};

// The rotor time constants: 40 ms (paper 000's motor), 89 ms (750 W), 0.26 s (7.5 kW), 0.46 s
// (37 kW); cold (0.6x Rr) 1.67x that. The 37 kW estimate needs about 6 s of load to come within
// 1 %, and its load comes at 1.6 s; the 7.5 kW's at 2.5 s, and at its slip tangent (0.6) the
// rate is 0.55 / tau_c: from a cold rotor (1.67x) it needs about 8 s of load; the 750 W's sine
// passes through zero speed, where the estimate freezes, so it takes about 2 s, and so does the
// 0.55 kW's (69 ms). The 15 kW's (0.35 s) has its load (slip tangent 1.1, rate 1.1 / tau_c) half
// of the time: from a cold rotor (tau_c = 2.4 s) about 13 s to come within 3 %, 18 s within 1 %.
const Case kCases[] = {
    {"hal_sim/scenarios/seed000_realistic.toml", 8.0, 0.5},
    {"tests/data/scenarios/small_4pole_750W_realistic.toml", 8.0, 3.0},
    {"tests/data/scenarios/six_pole_7kW_realistic.toml", 16.0, 12.0},
    {"hal_sim/scenarios/seed001_realistic.toml", 12.0, 8.0},
    {"hal_sim/scenarios/seed001_ifoc.toml", 12.0, 8.0},
    {"tests/data/scenarios/two_pole_550W_realistic.toml", 8.0, 3.0},
    {"tests/data/scenarios/eight_pole_15kW_realistic.toml", 24.0, 16.0},
};

Scenario scenario(const Case& c, std::vector<std::string> overrides) {
  overrides.push_back("simulation.duration_s=" + std::to_string(c.duration_s));
  overrides.push_back("metrics.settle_s=" + std::to_string(c.settle_s));
  return load_scenario(test::source_path(c.file), overrides);
}

/// The squared-flux reference the metric compares against: the rotor's, or the stator's (iol).
double flux2_ref_Wb2(const Scenario& s) {
  return s.controller == "iol" ? s.stator_flux2_Wb2 : s.flux2_Wb2;
}

class Mismatch : public ::testing::TestWithParam<Case> {};

TEST_P(Mismatch, TrackingRemovesWhatARotorResistanceErrorCosts) {
  const Case& c = GetParam();
  const Scenario nominal = scenario(c, {});
  for (const double scale : {1.5, 0.6}) {
    const std::string rr = std::to_string(scale * nominal.motor.Rr_Ohm);
    const std::string plant_rr = "plant.Rr_Ohm=" + rr;
    // Matched: the controller knows the rotor as it is (what the mismatch is measured against;
    // a colder or hotter rotor changes the motor's own response).
    const Summary matched = run_scenario(
        scenario(c, {plant_rr, "motor.Rr_Ohm=" + rr, "drive.rotor_resistance_tracking=false"}));
    ASSERT_TRUE(matched.faults.empty());
    const Summary on = run_scenario(scenario(c, {plant_rr}));
    const Summary off =
        run_scenario(scenario(c, {plant_rr, "drive.rotor_resistance_tracking=false"}));
    std::printf(
        "%s Rr x%.1f: speed rms %.4g (off %.4g, matched %.4g) rad/s, flux2 rms %.3g "
        "(off %.3g) Wb^2, Rr %.5g of %.5g Ohm, %u retunes\n",
        c.file, scale, on.speed_rms_err_rad_s, off.speed_rms_err_rad_s, matched.speed_rms_err_rad_s,
        on.flux2_rms_err_Wb2, off.flux2_rms_err_Wb2, on.rr_estimate_final_Ohm,
        on.plant_Rr_final_Ohm, on.rr_retunes);
    // The acceptance of docs/robustness.md: no faults, the estimate within 3 % of the plant's,
    // the speed error within 1.3x of the matched run's, the squared flux within 2 % of its
    // reference.
    EXPECT_TRUE(on.faults.empty()) << c.file << " x" << scale;
    EXPECT_NEAR(on.rr_estimate_final_Ohm / on.plant_Rr_final_Ohm, 1.0, 0.03)
        << c.file << " x" << scale;
    EXPECT_LE(on.speed_rms_err_rad_s, 1.3 * matched.speed_rms_err_rad_s) << c.file << " x" << scale;
    EXPECT_LE(on.flux2_rms_err_Wb2, 0.02 * flux2_ref_Wb2(nominal)) << c.file << " x" << scale;
    // Without tracking the flux is off by far more (what the tracking is for): at least 5x
    // the tracked error, and over 5 % of its reference.
    EXPECT_GT(off.flux2_rms_err_Wb2, 5.0 * on.flux2_rms_err_Wb2) << c.file << " x" << scale;
    EXPECT_GT(off.flux2_rms_err_Wb2, 0.05 * flux2_ref_Wb2(nominal)) << c.file << " x" << scale;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryLawAndMotor, Mismatch, ::testing::ValuesIn(kCases));

TEST(RotorHeating, TheEstimateFollowsTheRotorAsItHeatsUnderLoad) {
  // 20 s, the plant's rotor resistance from 1.0x to 1.5x (2.5 %/s). At the documented rate the
  // estimate lags a ramp by (ramp rate) x (time constant) / (2 x^2/(1 + x^2)): 0.4 % for the
  // paper-000 motor (tau_c = 0.16 s), 1.3 % for the 750 W motor (0.4 s, x ~ 0.9). The issue's
  // bound is 5 % after the first 2 s.
  for (const char* file : {"hal_sim/scenarios/seed000_realistic.toml",
                           "tests/data/scenarios/small_4pole_750W_realistic.toml"}) {
    const Scenario s =
        load_scenario(test::source_path(file),
                      {"simulation.duration_s=20", "metrics.settle_s=2", "plant.Rr_scale_end=1.5"});
    const Summary r = run_scenario(s);
    std::printf(
        "%s heating 1.0x -> 1.5x: largest estimate error after 2 s %.2f %%, final %.5g "
        "of %.5g Ohm\n",
        file, 100 * r.rr_rel_err_max, r.rr_estimate_final_Ohm, r.plant_Rr_final_Ohm);
    EXPECT_TRUE(r.faults.empty()) << file;
    EXPECT_NEAR(r.plant_Rr_final_Ohm / s.plant.Rr_Ohm, 1.5, 1e-3) << file;
    EXPECT_LT(r.rr_rel_err_max, 0.05) << file;
  }
}

TEST(RotorResistanceSwap, AModelSwappedInOnTheSameResistanceChangesNothing) {
  // The adaptation frozen (infinite time constant) and a rebuild at every interval (share 0):
  // the drive swaps in a new model every 50 ms, on exactly the same rotor resistance (a value
  // float represents, so that the estimate's trip through the float atomic keeps it). Every
  // part must take its state over from the old model, so that the run is the same, bit for
  // bit, as one without a swap. A part that forgot a state (an integrator, an observer) would
  // show at once.
  for (const char* file :
       {"hal_sim/scenarios/seed000_realistic.toml", "hal_sim/scenarios/seed001_realistic.toml",
        "hal_sim/scenarios/seed001_ifoc.toml"}) {
    Scenario s = load_scenario(test::source_path(file), {"simulation.duration_s=3"});
    s.motor.Rr_Ohm = s.plant.Rr_Ohm = double(float(s.motor.Rr_Ohm));
    s.rotor_resistance_tracking = false;
    std::vector<SimRow> fixed, swapped;
    const Summary without = run_scenario(s, {[&](const SimRow& row) { fixed.push_back(row); }});
    s.rotor_resistance_tracking = true;
    s.rr_convergence_time_constant_s = INFINITY;
    s.rr_retune_share = 0.0;
    const Summary with = run_scenario(s, {[&](const SimRow& row) { swapped.push_back(row); }});
    EXPECT_TRUE(without.faults.empty()) << file;
    EXPECT_GT(with.rr_retunes, 40u) << file;  // 3 s at one per 50 ms, less the start-up
    ASSERT_EQ(fixed.size(), swapped.size());
    for (std::size_t k = 0; k < fixed.size(); ++k) {
      ASSERT_EQ(fixed[k].omega_mech_rad_s, swapped[k].omega_mech_rad_s) << file << " tick " << k;
      ASSERT_EQ(fixed[k].i_alpha_A, swapped[k].i_alpha_A) << file << " tick " << k;
      ASSERT_EQ(fixed[k].flux2_est_Wb2, swapped[k].flux2_est_Wb2) << file << " tick " << k;
    }
  }
}

}  // namespace
}  // namespace imd::sim
