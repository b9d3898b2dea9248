// Healthy motors on cases that no scenario file and no other sweep writes: each case draws a
// motor of the six, a law, a rotor-flux reference, a plant that differs from the record
// (within the robustness maps' ranges), a speed profile of steps with reversals, and a load of
// steps of either sign (overhauling loads among them), from a fixed seed. Nothing may trip: the
// protections' thresholds follow from the motor, the board and the period, so a case they
// were not written for is no reason to trip. Each case's draw is printed when it fails, so it
// can be run again on its own (IMD_RANDOM_CASES=first:count).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "fault_events_text.hpp"
#include "firmware/protection/protection_config.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/law_variant.hpp"
#include "hal_sim/scenario.hpp"
#include "realistic_boards.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const char* kLaws[] = {"dsmc", "ifoc", "iol"};

struct Case {
  const char* file;
  const char* law;
  double flux_share, Rr, Rs, Lm, J;  ///< the reference's share; plant over record
  double speed_share[4], load_share[4];
  int seed;
};

/// The draw: the plant within one of docs/robustness.md's two maps (the resistances, or the
/// magnetizing inductance and the inertia), the rotor resistance from a cold rotor to a hot one
/// (0.5 to 2); speeds within 0.8 of base speed (the voltage the drive keeps in reserve); loads
/// within half the torque at the current limit, so that the speed loops keep authority over
/// the worst plant (J three times the record's accelerates a third as fast, and no law may be
/// asked for more than it has). libstdc++'s distributions make the draws the same everywhere
/// this project builds.
Case draw(std::mt19937_64& rng) {
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  Case c{};
  c.file = test_boards::kRealistic[std::uniform_int_distribution<int>(0, 5)(rng)];
  c.law = kLaws[std::uniform_int_distribution<int>(0, 2)(rng)];
  c.flux_share = uniform(0.6, 1.0);
  c.Rr = c.Rs = c.Lm = c.J = 1.0;
  if (std::uniform_int_distribution<int>(0, 1)(rng) == 0) {  // the resistances' map
    c.Rr = std::exp(uniform(std::log(0.5), std::log(2.0)));
    c.Rs = uniform(0.7, 1.3);
  } else {  // the inductance's and the inertia's
    c.Lm = uniform(0.8, 1.1);
    c.J = std::exp(uniform(std::log(0.5), std::log(3.0)));
  }
  for (double& w : c.speed_share) w = uniform(-0.8, 0.8);
  for (double& l : c.load_share) l = uniform(-0.5, 0.5);
  c.seed = std::uniform_int_distribution<int>(1, 1000)(rng);
  return c;
}

std::string text(const Case& c) {
  char buffer[320];
  std::snprintf(buffer, sizeof buffer,
                "%s %s flux x%.2f plant Rr x%.2f Rs x%.2f Lm x%.2f J x%.2f speeds %.2f %.2f %.2f "
                "%.2f loads %.2f %.2f %.2f %.2f seed %d",
                c.file, c.law, c.flux_share, c.Rr, c.Rs, c.Lm, c.J, c.speed_share[0],
                c.speed_share[1], c.speed_share[2], c.speed_share[3], c.load_share[0],
                c.load_share[1], c.load_share[2], c.load_share[3], c.seed);
  return buffer;
}

Scenario scenario_of(const Case& c) {
  Scenario s = test_boards::with_plant_error(
      with_law(load_scenario(test::source_path(c.file),
                             {"simulation.seed=" + std::to_string(c.seed)}),
               c.law, c.flux_share),
      c.Rr, c.Rs, c.Lm, c.J);
  // The draw's shares (at most 0.8) of the lower of base speed and the overspeed trip (the
  // 0.55 kW motor's base speed at 0.6 of its flux is 570 rad/s, beyond the default 400).
  const double overspeed_rad_s =
      s.protection.overspeed_rad_s.value_or(double(firmware::ProtectionConfig{}.overspeed_rad_s));
  const double w = std::min(base_speed_rad_s(s, s.flux2_Wb2), overspeed_rad_s);
  const double t = torque_at_current_limit_Nm(s, s.flux2_Wb2);
  // Steps 0.7 s apart from when the drive runs on the record's motor; each ramps over 0.3 s of
  // base speed on the record's inertia (the drive's own acceleration limit).
  const double t0 = test_boards::running_by_s(s);
  s.speed = speed_steps({{t0, c.speed_share[0] * w},
                         {t0 + 0.7, c.speed_share[1] * w},
                         {t0 + 1.4, c.speed_share[2] * w},
                         {t0 + 2.1, c.speed_share[3] * w}});
  s.load = load_steps({{t0 + 0.35, c.load_share[0] * t},
                       {t0 + 1.05, c.load_share[1] * t},
                       {t0 + 1.75, c.load_share[2] * t},
                       {t0 + 2.45, c.load_share[3] * t}});
  s.max_accel_rad_s2 = w / 0.3;
  s.duration_s = t0 + 2.8;
  s.settle_s = t0;
  return s;
}

TEST(RandomHealthySweep, NothingTripsOnCasesNoScenarioWrites) {
  int first = 0, count = 200;
  if (const char* range = std::getenv("IMD_RANDOM_CASES")) {
    ASSERT_TRUE(std::sscanf(range, "%d:%d", &first, &count) == 2 && first >= 0 && count > 0)
        << "IMD_RANDOM_CASES=" << range << ": expected first:count, e.g. 200:1000";
  }
  std::mt19937_64 rng(20261128);
  int runs = 0;
  for (int i = 0; i < first + count; ++i) {
    const Case c = draw(rng);
    if (i < first) continue;
    const Scenario s = scenario_of(c);
    const Summary r = run_scenario(s);
    ++runs;
    // The profile was run: running before its second step. (running_by_s is the record's
    // motor's time; a stator of 1.3 times its resistance makes the 7.5 kW motor about 3 %
    // later, which the magnetizing timeout, twice that time, allows for.)
    EXPECT_GT(r.running_from_s, 0.0) << "case " << i << ": " << text(c);
    EXPECT_LT(r.running_from_s, test_boards::running_by_s(s) + 0.7)
        << "case " << i << ": " << text(c);
    EXPECT_TRUE(r.faults.empty()) << "case " << i << ": " << text(c) << ": " << faults_text(r);
  }
  std::printf("random healthy cases: %d runs\n", runs);
}

}  // namespace
}  // namespace imd::sim
