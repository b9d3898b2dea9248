// The rotor-resistance tracker through speed reversals under load steps, on every test motor
// and law, at 10 and 20 kHz, on profiles no shipped scenario runs. The tracker's powers are
// low-passed over a rotor time constant; right after the stator frequency passes through zero
// they still hold the powers of the slow frequencies around it, near zero, whose ratio the
// inverter's voltage errors decide. Adapting on that ratio moved the 0.75 kW motor's estimate
// by 5.8 % at 20 kHz after a load step at a zero crossing, and the frozen estimate then stayed
// there until the load came back (control/rotor_resistance_mras.hpp now also asks the filtered
// powers for the minimum frequency). On the 0.55 kW motor's light rotor the speed estimate lagged
// a load step by up to 8.6 rad/s, which moved the estimate by 3.5 % (the tracker now takes the
// period's mean speed from the encoder's counts).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "fault_events_text.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/law_variant.hpp"
#include "hal_sim/scenario.hpp"
#include "realistic_boards.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

struct Board {
  const char* file;
  const char* laws[2];
};

const Board kBoards[] = {
    {"hal_sim/scenarios/seed000_realistic.toml", {"dsmc", "ifoc"}},
    {"hal_sim/scenarios/seed001_realistic.toml", {"iol", "ifoc"}},
    {"tests/data/scenarios/small_4pole_750W_realistic.toml", {"dsmc", "ifoc"}},
    {"tests/data/scenarios/six_pole_7kW_realistic.toml", {"dsmc", "ifoc"}},
    {"tests/data/scenarios/two_pole_550W_realistic.toml", {"dsmc", "ifoc"}},
    {"tests/data/scenarios/eight_pole_15kW_realistic.toml", {"dsmc", "ifoc"}},
};

// A reversing speed sine of 0.4 of base speed, slow enough that accelerating the rotor takes at
// most a fifth of the torque the current limit allows (and at most 0.5 Hz), and a load that
// steps between none and 0.4 of that torque `shift_s` after each zero crossing of the speed
// reference: two periods of the sine, four crossings. The record's rotor resistance is the
// plant's (`rr_scale` of the motor file's), so the estimate starts at the true value and every
// move it makes is an error.
Scenario reversal(const char* file, const char* law, double period_s, double rr_scale,
                  double shift_tau_r) {
  Scenario s = with_law(
      load_scenario(test::source_path(file), {"drive.sample_period_s=" + std::to_string(period_s)}),
      law);
  const double rr_Ohm = rr_scale * s.motor.Rr_Ohm;
  s.motor.Rr_Ohm = s.plant.Rr_Ohm = rr_Ohm;
  s.rotor_resistance_tracking = true;
  const double w = 0.4 * base_speed_rad_s(s, s.flux2_Wb2);
  const double t_lim = torque_at_current_limit_Nm(s, s.flux2_Wb2);
  const double f_Hz = std::min(0.5, 0.2 * t_lim / (s.plant.J_kgm2 * w * 2 * std::numbers::pi));
  s.speed.kind = SpeedProfile::Kind::sine;
  s.speed.amplitude_rad_s = w;
  s.speed.frequency_Hz = f_Hz;
  s.speed.offset_rad_s = 0.0;
  s.max_accel_rad_s2 = std::numeric_limits<double>::infinity();
  const double half_s = 0.5 / f_Hz, shift_s = shift_tau_r * s.plant.Lr_H / rr_Ohm;
  s.load = LoadProfile{};
  s.load.kind = LoadProfile::Kind::steps;
  // From the first crossing whose load step comes once the drive runs: a load on a rotor not
  // yet magnetized turns it, and a slow rotor (the 15 kW's, cold: 2.2 s) may take several
  // half periods to magnetize.
  const int first = std::max(1, int(std::ceil((test_boards::running_by_s(s) - shift_s) / half_s)));
  for (int k = first; k < first + 4; ++k) {  // high after the 1st and 3rd, none after the others
    s.load.times_s[s.load.step_count] = k * half_s + shift_s;
    s.load.values_Nm[s.load.step_count++] = ((k - first) % 2 == 0) ? 0.4 * t_lim : 0.0;
  }
  s.duration_s = (first + 3) * half_s + 0.5 * half_s;
  s.settle_s = 0.0;  // the estimate starts right: its largest error over the whole run
  return s;
}

TEST(RrReversalSweep, AReversalUnderALoadStepKeepsTheEstimate) {
  // Six motors (0.55 kW to the paper-001 37 kW machine, one to four pole pairs), two laws each, 10
  // and 20 kHz, a cold and a hot rotor, the load step a rotor time constant before the
  // crossing, at it and one after. The bound is docs/robustness.md's acceptance for the
  // estimate: within 3 % of the plant's rotor resistance.
  int runs = 0;
  double worst = 0.0;
  for (const Board& b : kBoards) {
    for (const char* law : b.laws) {
      for (const double period_s : {1e-4, 5e-5}) {
        for (const double rr_scale : {0.6, 1.5}) {
          for (const double shift_tau_r : {-1.0, 0.0, 1.0}) {
            const Summary r = run_scenario(reversal(b.file, law, period_s, rr_scale, shift_tau_r));
            ++runs;
            worst = std::max(worst, r.rr_rel_err_max);
            const std::string what = std::string(b.file) + " " + law + " T " +
                                     std::to_string(period_s) + " Rr x" + std::to_string(rr_scale) +
                                     " shift " + std::to_string(shift_tau_r) + " tau_r";
            EXPECT_TRUE(r.faults.empty()) << what << ": " << faults_text(r);
            EXPECT_LE(r.rr_rel_err_max, 0.03) << what;
          }
        }
      }
    }
  }
  std::printf("reversals under load steps: %d runs, largest estimate error %.2f %%\n", runs,
              100 * worst);
}

}  // namespace
}  // namespace imd::sim
