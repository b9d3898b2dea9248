// The seed-001 scenarios end to end: the current-fed controller of paper 001 in the firmware's
// tick, on the simulated board.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "control/current_fed_model.hpp"
#include "firmware/drive_state.hpp"
#include "float_design_skip.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

Scenario scenario(const std::string& name, const std::vector<std::string>& overrides = {}) {
  return load_scenario(test::source_path("hal_sim/scenarios/" + name), overrides);
}

TEST(Seed001Paper, DecouplesExactlyAndSettlesTheFlux) {
  const Scenario s = scenario("seed001_paper.toml");
  std::vector<SimRow> boundaries;
  bool finite = true;
  const Summary r = run_scenario(s, {[&](const SimRow& row) {
                                       finite = finite && std::isfinite(row.stator_flux2_Wb2) &&
                                                std::isfinite(row.omega_mech_rad_s) &&
                                                std::isfinite(row.torque_Nm);
                                       if (row.iol_boundary) boundaries.push_back(row);
                                     },
                                     {}});
  ASSERT_TRUE(r.faults.empty());
  EXPECT_TRUE(finite);  // no state diverges over the 3 s (internal dynamics)
  ASSERT_GT(boundaries.size(), 2900u);

  // (25): torque(k+1) = v1(k) and y2(k+1) = v2(k). The plant integrates the current-fed motor
  // with RK4 (h = 10 us) against the exact model; their one-step agreement is 1e-14
  // (CurrentFedModel.OneStepMatchesTheCurrentFedPlant), so 1e-9 leaves room for 3000 steps of
  // rounding. Torque errors are relative to max(|v1|, 1 N m): v1 is 0 before the step.
  double worst_torque = 0.0, worst_y2 = 0.0;
  for (std::size_t k = 1; k + 1 < boundaries.size(); ++k) {
    const SimRow& now = boundaries[k];
    const SimRow& next = boundaries[k + 1];
    worst_torque = std::max(worst_torque, std::abs(next.torque_Nm - now.torque_ref_Nm) /
                                              std::max(std::abs(now.torque_ref_Nm), 1.0));
    worst_y2 = std::max(worst_y2, std::abs(next.y2 - now.y2_ref) / std::abs(now.y2_ref));
  }
  std::printf("seed001 paper: worst relative error torque %.2e, y2 %.2e\n", worst_torque, worst_y2);
  // Exact to double rounding with double coefficients; float's (the float-design build) put
  // the plant and the law's model 1e-7 apart, which this exactness does not allow for.
  if (kDoubleDesigns) {
    EXPECT_LE(worst_torque, 1e-9);
    EXPECT_LE(worst_y2, 1e-9);
    // The references reach the law at the right tick: v1 is the torque wanted at the next
    // boundary, so the torque is 120 N m from the first boundary at or after 1 s, 0 before.
    for (std::size_t k = 1; k < boundaries.size(); ++k) {
      if (boundaries[k].t_s >= 1.0 && boundaries[k - 1].t_s < 1.0) {
        EXPECT_NEAR(boundaries[k].torque_Nm, 120.0, 1e-9 * 120.0);
        EXPECT_NEAR(boundaries[k - 1].torque_Nm, 0.0, 1e-9);
      }
    }
  }

  // The squared stator flux settles within 1 % of the target set through (21)...
  const SimRow& last = boundaries.back();
  EXPECT_NEAR(last.stator_flux2_Wb2, s.stator_flux2_Wb2, 0.01 * s.stator_flux2_Wb2);
  // ... and slightly above it, by what the slip explains: (21) drops cos(w_sl T0), and in steady
  // state F = (1 - e) F_ref / (cos(w_sl T0) - e). The slip angle per period is the rotor
  // flux's turn in the rotor frame. Measured: 0.05 % apart at 3 s. What is left of the
  // flux transient after the torque step (pole e = 0.998 per period, 2 s: e^-4.3 of a 0.2 %
  // change) stays below 2 % of the excess.
  const SimRow& before = boundaries[boundaries.size() - 2];
  const double slip_T0 =
      std::atan2(last.flux_B_Wb, last.flux_A_Wb) - std::atan2(before.flux_B_Wb, before.flux_A_Wb);
  const double e = control::discretize_current_fed(s.motor, s.iol_period_s).flux_decay;
  const double predicted = (1.0 - e) * s.stator_flux2_Wb2 / (std::cos(slip_T0) - e);
  const double excess = last.stator_flux2_Wb2 - s.stator_flux2_Wb2;
  EXPECT_GT(excess, 0.0);
  EXPECT_NEAR(excess, predicted - s.stator_flux2_Wb2, 0.02 * (predicted - s.stator_flux2_Wb2));
  std::printf("seed001 paper: flux^2 %.6f (target %.1f), slip %.3f rad/s, predicted %.6f\n",
              last.stator_flux2_Wb2, s.stator_flux2_Wb2, slip_T0 / s.iol_period_s, predicted);
}

TEST(Seed001Paper, MetricsAndStartUpAreRight) {
  IMD_SKIP_IF_FLOAT_DESIGN("the torque error is at double rounding level (1e-9) only");
  // The summary's torque error spans the torque step when settle_s precedes it: it compares
  // each boundary with the command of the one before, so it stays at rounding level.
  const Summary r = run_scenario(scenario("seed001_paper.toml", {"metrics.settle_s=0.5"}));
  EXPECT_LE(r.torque_rms_err_Nm, 1e-9 * 120.0);
  EXPECT_LE(r.i_hold_rms_err_A, 1e-9);  // the ideal source holds the current exactly
  // The default magnetizing current of the iol is the one that holds the stator-flux target at
  // zero slip, sqrt(F)/Ls = 31.50 A for the 37 kW motor; an ideal source imposes it exactly.
  const Scenario s = scenario("seed001_paper.toml", {"drive.magnetized_fraction=0.5"});
  double magnetizing_current = 0.0;
  run_scenario(s,
               {[&](const SimRow& row) {
                  if (row.state == int(imd::firmware::DriveState::magnetizing) && row.t_s > 0.01) {
                    magnetizing_current = std::hypot(row.i_alpha_A, row.i_beta_A);
                  }
                },
                {}});
  EXPECT_NEAR(magnetizing_current, std::sqrt(s.stator_flux2_Wb2) / s.motor.Ls_H, 1e-9);
}

TEST(Seed001OuterLoop, FluxLoopRemovesTheSlipExcess) {
  // With the loop of Fig. 5 the squared stator flux sits on its target at the boundaries despite
  // the slip (the integrator takes up what (21) neglects); decoupling is unchanged.
  const Scenario s = scenario("seed001_outer_loop.toml");
  std::vector<SimRow> boundaries;
  const Summary r = run_scenario(s, {[&](const SimRow& row) {
                                       if (row.iol_boundary) boundaries.push_back(row);
                                     },
                                     {}});
  ASSERT_TRUE(r.faults.empty());
  ASSERT_GT(boundaries.size(), 2900u);
  // The slip changes at 1 s and 1.6 s; the loop's double pole at 0.905 per period leaves
  // nothing measurable after 1.4 s: the excess of the open loop (2e-3) is gone to 1e-6.
  EXPECT_NEAR(boundaries.back().stator_flux2_Wb2, s.stator_flux2_Wb2, 1e-6);
  // With one tick of latency the current source gets u(k) one tick early: decoupling holds,
  // to double rounding with double coefficients (as above).
  const Summary late =
      run_scenario(scenario("seed001_outer_loop.toml", {"simulation.pwm_latency_ticks=1"}));
  if (kDoubleDesigns) {
    EXPECT_LE(r.torque_rms_err_Nm, 1e-9 * 120.0);
    EXPECT_LE(late.torque_rms_err_Nm, 1e-9 * 120.0);
  }
  // The loop inverts the magnitude relation of y2, so the start from 1 % of the flux does not
  // overshoot wildly (a linear v2 would reach 4 Wb^2, 400 %): measured 10.8 %.
  double peak = 0.0;
  for (const SimRow& row : boundaries) peak = std::max(peak, row.stator_flux2_Wb2);
  EXPECT_LE(peak, 1.15 * s.stator_flux2_Wb2);
}

TEST(Seed001Realistic, TracksTorqueAndHoldsTheFluxOnAVoltageInverter) {
  const Scenario s = scenario("seed001_realistic.toml");
  double flux_dev_speed_step = 0.0, flux_dev_load_step = 0.0;
  const Summary r = run_scenario(s, {[&](const SimRow& row) {
                                       const double dev =
                                           std::abs(row.stator_flux2_Wb2 - s.stator_flux2_Wb2);
                                       if (row.t_s >= 0.6 && row.t_s < 1.0)
                                         flux_dev_speed_step = std::max(flux_dev_speed_step, dev);
                                       if (row.t_s >= 1.6 && row.t_s < 2.0)
                                         flux_dev_load_step = std::max(flux_dev_load_step, dev);
                                     },
                                     {}});
  ASSERT_TRUE(r.faults.empty());
  std::printf(
      "seed001 realistic: torque rms err %.3f N m, flux dev %.4f / %.4f, speed rms %.4f rad/s, "
      "i hold rms %.3f A, i peak %.1f A\n",
      r.torque_rms_err_Nm, flux_dev_speed_step, flux_dev_load_step, r.speed_rms_err_rad_s,
      r.i_hold_rms_err_A, r.i_peak_total_A);
  // Torque against the law's command one T0 earlier, after 2 s: <= 2 % of the 100 N m load step
  // (measured 1.16 N m; with ideal sensors 1e-3 N m: the ADC and encoder noise make the rest).
  EXPECT_LE(r.torque_rms_err_Nm, 0.02 * 100.0);
  // The squared stator flux moves by <= 1 % at the torque demand of the speed step and at the
  // load step (the coupling the decoupling leaves on a real board).
  EXPECT_LE(flux_dev_speed_step, 0.01 * s.stator_flux2_Wb2);
  EXPECT_LE(flux_dev_load_step, 0.01 * s.stator_flux2_Wb2);
  EXPECT_LE(r.i_peak_total_A, s.i_max_A);
  // The speed error after 2 s, documented in docs/iol.md (measured 0.046 rad/s RMS); 3x room
  // for the noise.
  EXPECT_LE(r.speed_rms_err_rad_s, 0.15);
}

}  // namespace
}  // namespace imd::sim
