// Paper 001's law at the voltage limit on the simulated board: near base speed, under loads
// that overhaul the motor, through a reversal, on six motors at the file's flux and at 0.6 of
// it. The law commands only currents its loop reaches within a period (control/current_reach.hpp,
// docs/iol.md "At the voltage limit"); before, a deceleration from 0.8 of base speed against
// an overhauling load left it a command the loop could not deliver, its model drifted from the
// motor period after period, and its stator flux collapsed into a singular_control trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "fault_events_text.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/law_variant.hpp"
#include "hal_sim/scenario.hpp"
#include "realistic_boards.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

TEST(IolVoltageLimitSweep, NearBaseSpeedUnderOverhaulingLoadsNothingTrips) {
  int runs = 0;
  for (const char* file : test_boards::kRealistic) {
    for (const double flux_share : {1.0, 0.6}) {
      for (const int seed : {1, 2}) {
        Scenario s = with_law(
            load_scenario(test::source_path(file), {"simulation.seed=" + std::to_string(seed)}),
            "iol", flux_share);
        const double w = base_speed_rad_s(s, s.flux2_Wb2);
        const double t = torque_at_current_limit_Nm(s, s.flux2_Wb2);
        // Once running (all are by 1.5 s), up to 0.8 of base speed (within 0.8 of the over-speed
        // trip) under a load that drives the motor forward (half the torque at the current
        // limit), a step down against it, then a reversal against one that drives it backward,
        // and a step towards zero. Each segment lasts what a quarter of the torque at the current
        // limit (the load takes half, the voltage limit some) needs for its change of speed,
        // plus 0.5 s.
        const double top = std::min(0.8 * w, 0.8 * s.protection.overspeed_rad_s.value_or(400.0));
        const auto lasts_s = [&](double change_rad_s) {
          return s.motor.J_kgm2 * change_rad_s / (0.25 * t) + 0.5;
        };
        const double t1 = 1.5, t2 = t1 + lasts_s(top), t3 = t2 + lasts_s(0.06 * top),
                     t4 = t3 + lasts_s(1.94 * top);
        s.speed = speed_steps({{t1, top}, {t2, 0.94 * top}, {t3, -top}, {t4, -0.94 * top}});
        s.load = load_steps({{t1, -0.5 * t}, {t3, 0.5 * t}});
        s.max_accel_rad_s2 = w / 0.3;  // the ramp: a full step in 0.3 s of base speed
        s.duration_s = t4 + lasts_s(0.06 * top);
        s.settle_s = s.duration_s - 0.4;
        const Summary r = run_scenario(s);
        ++runs;
        const std::string run = std::string(file) + " flux x" + std::to_string(flux_share) +
                                " seed " + std::to_string(seed);
        EXPECT_LT(r.running_from_s, 1.5) << run;
        EXPECT_TRUE(r.faults.empty()) << run << ": " << faults_text(r);
        // Over the last 0.4 s of its last segment the speed loop (30 to 100 rad/s of bandwidth)
        // has long settled: what is left is the encoder's and the ADC's noise, far below 1 % of
        // base speed. A law that lost its flux or its torque stays far from it.
        EXPECT_LT(r.speed_rms_err_rad_s, 0.01 * w) << run;
        std::printf("%s: top %.1f rad/s (base %.1f), speed RMS error %.4f rad/s\n", run.c_str(),
                    top, w, r.speed_rms_err_rad_s);
      }
    }
  }
  std::printf("IOL at the voltage limit: %d runs\n", runs);
}

}  // namespace
}  // namespace imd::sim
