// The encoder check on the simulated board (firmware/protection/encoder_check.hpp): no false
// trip over a sweep of low speeds, load steps and noise seeds, beside the test that it finds
// a frozen encoder. The paper-000 motor on its realistic board; the check allows loads up to
// 3/4 of the torque at the current limit (2.56 N m here), and the sweep's steps go to 2 N m.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const char* kBoard = "hal_sim/scenarios/seed000_realistic.toml";

/// A constant speed reference and a load step at 1.5 s (the square load's rising edge).
std::vector<std::string> profile(const std::string& law, double speed_rad_s, double load_Nm,
                                 int seed) {
  return {"drive.controller=" + law,
          "reference.speed.amplitude_rad_s=0",
          "reference.speed.offset_rad_s=" + std::to_string(speed_rad_s),
          "load.period_s=3.0",
          "load.high_Nm=" + std::to_string(load_Nm),
          "simulation.duration_s=2.5",
          "metrics.settle_s=1.0",
          "simulation.seed=" + std::to_string(seed)};
}

TEST(EncoderCheckSweep, NoFalseTripAtLowSpeedUnderLoadSteps) {
  // Speeds 0..5 rad/s (a count every 0.8 ms at 1 rad/s, none for seconds at 0), load steps
  // 0.2..2 N m that stop the rotor for a moment at the lowest speeds, five noise seeds, the
  // two voltage-fed laws: 180 runs, none may trip anything.
  int runs = 0;
  for (const char* law : {"dsmc", "ifoc"}) {
    for (const double speed : {0.0, 0.25, 0.5, 1.0, 2.0, 5.0}) {
      for (const double load : {0.2, 1.0, 2.0}) {
        for (const int seed : {1, 2, 3, 4, 5}) {
          const Summary r =
              run_scenario(load_scenario(test::source_path(kBoard), profile(law, speed, load, seed)));
          ++runs;
          EXPECT_TRUE(r.faults.empty()) << law << " " << speed << " rad/s, " << load << " N m, seed "
                                        << seed << ": " << r.faults.front().code << " at "
                                        << r.faults.front().detected_at_s << " s";
        }
      }
    }
  }
  std::printf("encoder sweep: %d runs\n", runs);
}

TEST(EncoderCheckSweep, FindsAFrozenEncoderAtEverySpeed) {
  // Frozen at 1.5 s at 1, 10 and 100 rad/s with 0.5 N m of load. At 10 and 100 rad/s the
  // rotor outruns any braking within the bound in a tick or two. At 1 rad/s the worst load
  // could have stopped it, so the check waits for the law's torque to pass the bound: the
  // speed loop sees the speed stop and raises its torque (the IFOC's PI integrates 1 rad/s of
  // error at ki = J w^2 / 4 = 25 N m/s per rad/s, so 2 N m more takes about 80 ms), then the
  // bound climbs for a few tens of ms. 0.3 s bounds both laws.
  for (const char* law : {"dsmc", "ifoc"}) {
    for (const double speed : {1.0, 10.0, 100.0}) {
      std::vector<std::string> o = profile(law, speed, 0.5, 1);
      o.push_back("load.period_s=100.0");  // constant 0.5 N m from the start
      o.push_back("load.low_Nm=0.5");
      Scenario s = load_scenario(test::source_path(kBoard), o);
      FaultInjection f;
      f.at_s = 1.5;
      f.kind = FaultKind::encoder_loss;
      s.faults.push_back(f);
      const Summary r = run_scenario(s);
      ASSERT_FALSE(r.faults.empty()) << law << " " << speed;
      EXPECT_EQ(r.faults.front().code, "encoder") << law << " " << speed;
      const double latency_s = r.faults.front().detected_at_s - 1.5;
      std::printf("encoder frozen at %5.1f rad/s (%s): found after %.1f ms\n", speed, law,
                  latency_s * 1e3);
      EXPECT_GE(latency_s, 0.0);
      EXPECT_LT(latency_s, speed >= 10.0 ? 0.001 : 0.3) << law << " " << speed;
    }
  }
}

}  // namespace
}  // namespace imd::sim
