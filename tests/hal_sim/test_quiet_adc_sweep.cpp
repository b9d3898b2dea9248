// A quiet current converter: its noise below one code, so that a steady current reads the same
// codes tick after tick. The stuck-ADC check must not take that for a stuck converter: its
// evidence is the exact model's prediction, which holds still while the current does
// (firmware/protection/adc_stuck_check.hpp). The trap is a DC current with a voltage that
// still moves: the motor magnetized at standstill, or a stator frequency passing through zero
// under load, where the voltage follows the law's chatter and the back EMF. A check that summed
// voltage departures from one tick tripped there on the 7.5 kW motor at 0.08 codes of noise.
#include <gtest/gtest.h>

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

const auto& kBoards = test_boards::kRealistic;

double amps_per_code(const Scenario& s) {
  return 2.0 * s.adc.full_scale_A / double(1 << s.adc.bits);
}

/// When the profile below starts: once the drive runs and has held the rotor at standstill (a
/// DC current) for 0.4 s, and not before 0.6 s.
double start_s(const Scenario& s) {
  return std::max(0.6, test_boards::running_by_s(s) + 0.4);
}

// A profile no shipped scenario runs, on the board's motor: magnetized and held at standstill,
// forward to 0.3 of base speed, a load step to 0.4 of the torque at the current limit, then a
// slow reversal through zero speed under that load (the stator frequency crosses zero while the
// rotor turns) to -0.2 of base speed.
Scenario quiet_profile(const char* file, const char* law, double noise_codes) {
  Scenario s = with_law(load_scenario(test::source_path(file)), law);
  const double w = base_speed_rad_s(s, s.flux2_Wb2);
  const double t = torque_at_current_limit_Nm(s, s.flux2_Wb2);
  const double t0 = start_s(s);
  s.speed = speed_steps({{t0, 0.3 * w}, {t0 + 1.0, -0.2 * w}});
  s.load = load_steps({{t0 + 0.5, 0.4 * t}});
  s.max_accel_rad_s2 = w / 1.5;  // the reversal takes 0.75 s: slow through zero
  s.adc.noise_A = noise_codes * amps_per_code(s);
  s.duration_s = t0 + 2.2;
  return s;
}

TEST(QuietAdcSweep, AQuietConverterNeverTripsTheStuckCheck) {
  // Six motors (0.55 kW to the paper-001 37 kW machine, one to four pole pairs), every law, the
  // converter's noise from none to a third of a code rms (beyond that the codes rarely
  // repeat on all three phases), on the shipped realistic profile and on the one above: no
  // fault at all.
  int runs = 0;
  for (const char* file : kBoards) {
    for (const char* law : {"dsmc", "ifoc", "iol"}) {
      for (const double noise_codes : {0.0, 0.04, 0.08, 0.16, 0.33}) {
        for (const bool shipped : {true, false}) {
          Scenario s = shipped ? with_law(load_scenario(test::source_path(file)), law)
                               : quiet_profile(file, law, noise_codes);
          if (shipped) s.adc.noise_A = noise_codes * amps_per_code(s);
          const Summary r = run_scenario(s);
          ++runs;
          EXPECT_TRUE(r.faults.empty())
              << file << " " << law << " noise " << noise_codes << " codes, "
              << (shipped ? "shipped" : "unshipped") << " profile: " << faults_text(r);
        }
      }
    }
  }
  std::printf("quiet converters: %d runs\n", runs);
}

TEST(QuietAdcSweep, AStuckQuietConverterIsStillFound) {
  // The other side: the same quiet converters (no noise at all, the hardest case for the
  // evidence) freeze while the motor turns, 0.3 s after the profile starts (running forward),
  // 0.7 s (under load) and 1.4 s (reversing). Each is latched as adc_stuck within the run's
  // 0.5 s after it.
  int runs = 0;
  for (const char* file : kBoards) {
    for (const char* law : {"dsmc", "ifoc", "iol"}) {
      for (const double after_s : {0.3, 0.7, 1.4}) {
        Scenario s = quiet_profile(file, law, 0.0);
        const double at_s = start_s(s) + after_s;
        FaultInjection f;
        f.at_s = at_s;
        f.kind = FaultKind::adc_stuck;
        s.faults = {f};
        s.duration_s = at_s + 0.5;
        const Summary r = run_scenario(s);
        ++runs;
        ASSERT_FALSE(r.faults.empty()) << file << " " << law << " at " << at_s;
        EXPECT_EQ(r.faults.front().code, "adc_stuck")
            << file << " " << law << " at " << at_s << ": " << faults_text(r);
      }
    }
  }
  std::printf("quiet converters: %d stuck-ADC injections latched as adc_stuck\n", runs);
}

}  // namespace
}  // namespace imd::sim
