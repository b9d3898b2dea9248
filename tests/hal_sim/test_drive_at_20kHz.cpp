// The drive at 20 kHz (a 50 us period): on every test motor it tracks a reference and load the
// shipped scenarios do not use at least as well as at 10 kHz, and what depends on the period
// follows it: the designs placed in continuous time keep their poles' time constants, the
// windows and rates given as times double in ticks, and the protections answer in the same
// time (docs/performance-20kHz.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "control/encoder_observer.hpp"
#include "control/ifoc_design.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/identification/nameplate.hpp"
#include "firmware/laws/iol_stage.hpp"
#include "firmware/limitation.hpp"
#include "firmware/protocol/messages.hpp"
#include "float_design_skip.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

constexpr double k10kHz_s = 1e-4, k20kHz_s = 5e-5;

/// Each test motor's realistic scenario, with the speed (rad/s) and load (N m) scales of its
/// own profile, which the test's reference and load are shares of, and the time by which the
/// drive runs there (magnetized: about 0.2 s, the 7.5 kW motor's rotor time constant of
/// 0.26 s about 1.1 s).
struct MotorCase {
  const char* file;
  double speed_rad_s, load_Nm, running_s;
};
const MotorCase kMotors[] = {
    {"hal_sim/scenarios/seed000_realistic.toml", 100.0, 1.0, 0.2},
    {"hal_sim/scenarios/seed001_realistic.toml", 100.0, 100.0, 0.2},
    {"tests/data/scenarios/small_4pole_750W_realistic.toml", 100.0, 2.5, 0.2},
    {"tests/data/scenarios/six_pole_7kW_realistic.toml", 80.0, 40.0, 1.1},
};

Scenario at_period(const std::string& file, double period_s, std::vector<std::string> more = {}) {
  more.push_back("drive.sample_period_s=" + std::to_string(period_s));
  return load_scenario(test::source_path(file), more);
}

/// The run no shipped scenario makes: a speed sine offset from zero (0.3 + 0.5 sin(2 pi 0.5 t)
/// of the scale: the shipped sines are centred, at 0.25 Hz), under a load that steps on and then
/// reverses (+0.5, then -0.3 of the scale). A sine, not steps: the metrics compare with the
/// reference before its ramp, so steps would measure the ramp. The rotor-resistance tracker is
/// off: on the 0.75 kW motor its estimate wanders further from the true Rr at 20 kHz than at
/// 10 kHz (up to 5 % against 1.6 % over nearby profiles, with or without ADC noise, encoder
/// quantization and dead time), and the flux with it (docs/performance-20kHz.md); this
/// test is about the loops and the designs.
Scenario offset_sine(const MotorCase& m, double period_s, unsigned seed) {
  Scenario s = at_period(m.file, period_s,
                         {"simulation.seed=" + std::to_string(seed),
                          "drive.rotor_resistance_tracking=false"});
  s.speed = {};
  s.speed.kind = SpeedProfile::Kind::sine;
  s.speed.offset_rad_s = 0.3 * m.speed_rad_s;
  s.speed.amplitude_rad_s = 0.5 * m.speed_rad_s;
  s.speed.frequency_Hz = 0.5;
  // The start from rest to the offset is ramped; the sine's own acceleration, at most
  // 0.5 pi scale/s (157 rad/s^2), stays below every scenario's limit.
  if (!std::isfinite(s.max_accel_rad_s2)) s.max_accel_rad_s2 = 200.0;
  // Measured from 0.4 s after the drive runs: at the offset by then (0.15 s of ramp at most).
  s.settle_s = m.running_s + 0.4;
  s.load = {};
  s.load.kind = LoadProfile::Kind::steps;
  s.load.step_count = 2;
  s.load.times_s = {s.settle_s + 0.5, s.settle_s + 1.7};
  s.load.values_Nm = {0.5 * m.load_Nm, -0.3 * m.load_Nm};
  s.duration_s = s.settle_s + 3.0;
  return s;
}

struct Spread {
  double mean = 0.0, sd = 0.0;
};
Spread spread(const std::vector<double>& x) {
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / double(x.size());
  double sum2 = 0.0;
  for (const double v : x) sum2 += (v - mean) * (v - mean);
  return {mean, std::sqrt(sum2 / double(x.size() - 1))};
}

TEST(DriveAt20kHz, TracksOnEveryMotorAtLeastAsWellAsAt10kHz) {
  // Every pole the drive places is a continuous-time one (e^{-w delta}: the encoder observer's
  // 400 rad/s, the speed loop's min(2 pi f_s / 200, 100 rad/s), paper 001's law on T0 = 1 ms),
  // so the closed loop's dynamics are the same at both rates, while what the period costs (one
  // tick of PWM latency, the held inner feedback) halves. What differs between the rates'
  // errors beyond that is the ADC noise and encoder quantization, a random realization: each
  // rate runs kSeeds noise seeds, and the 20 kHz mean must not exceed the 10 kHz mean by more
  // than 4 standard deviations of a difference of two means of kSeeds draws
  // (sd sqrt(2 / kSeeds), the 10 kHz seeds' spread standing for both): one-sided 3e-5.
  constexpr unsigned kSeeds = 6;
  for (const MotorCase& m : kMotors) {
    std::vector<double> speed[2], flux[2];
    for (int rate = 0; rate < 2; ++rate) {
      for (unsigned seed = 1; seed <= kSeeds; ++seed) {
        const Scenario s = offset_sine(m, rate == 0 ? k10kHz_s : k20kHz_s, seed);
        const Summary r = run_scenario(s);
        EXPECT_TRUE(r.faults.empty()) << m.file << (rate ? " at 20 kHz" : " at 10 kHz");
        // It ran at the rate asked: the two rates' errors alike could also mean the period
        // override was lost.
        EXPECT_EQ(r.ticks, uint64_t(std::llround(s.duration_s / (rate == 0 ? k10kHz_s : k20kHz_s))))
            << m.file;
        // Running, and at the offset before the measured span (its ramp takes 0.15 s at most).
        EXPECT_GE(r.running_from_s, 0.0) << m.file;
        EXPECT_LT(r.running_from_s, m.running_s + 0.25) << m.file;
        speed[rate].push_back(r.speed_rms_err_rad_s);
        flux[rate].push_back(r.flux2_rms_err_Wb2);
      }
    }
    const double difference_sd = std::sqrt(2.0 / kSeeds);
    const Spread s10 = spread(speed[0]), s20 = spread(speed[1]);
    const Spread f10 = spread(flux[0]), f20 = spread(flux[1]);
    std::printf("%s: speed rms %.4f (sd %.4f) at 10 kHz, %.4f (sd %.4f) at 20 kHz; flux2 rms "
                "%.3e (sd %.1e), %.3e (sd %.1e)\n",
                m.file, s10.mean, s10.sd, s20.mean, s20.sd, f10.mean, f10.sd, f20.mean, f20.sd);
    EXPECT_LE(s20.mean, s10.mean + 4.0 * difference_sd * s10.sd) << m.file;
    EXPECT_LE(f20.mean, f10.mean + 4.0 * difference_sd * f10.sd) << m.file;
  }
}

TEST(DriveAt20kHz, ContinuousTimeDesignsKeepTheirTimeConstants) {
  IMD_SKIP_IF_FLOAT_DESIGN("the poles are checked to 1e-9 and 1e-12, double rounding");
  for (const test::TestMotor& motor : test::test_motors()) {
    for (const double period_s : {k10kHz_s, k20kHz_s}) {
      // The encoder observer's triple pole at e^{-400 delta}: the trace of its error matrix is
      // three times it (rounding of the gain's construction: 1e-9).
      const auto c = control::discretize_voltage_fed(motor.parameters, period_s);
      const auto error =
          control::encoder_observer_error_matrix(c, control::place_encoder_observer(c, 400.0));
      EXPECT_NEAR(error.trace() / 3.0, std::exp(-400.0 * period_s), 1e-9) << motor.name;
    }
    // The IFOC's current loop at f_s / 20: its pole per tick is the same, its bandwidth twice;
    // the speed loop's min(w_c / 10, w_obs / 4) = 100 rad/s at both rates.
    control::IfocSpec spec;
    spec.sample_period_s = k10kHz_s;
    const control::IfocGains g10 = control::design_ifoc(motor.parameters, spec);
    spec.sample_period_s = k20kHz_s;
    const control::IfocGains g20 = control::design_ifoc(motor.parameters, spec);
    EXPECT_NEAR(g20.current_bandwidth_rad_s, 2.0 * g10.current_bandwidth_rad_s, 1e-9);
    EXPECT_NEAR(g20.current_pole, g10.current_pole, 1e-12);
    EXPECT_DOUBLE_EQ(g20.speed_bandwidth_rad_s, g10.speed_bandwidth_rad_s);
  }
}

TEST(DriveAt20kHz, TimesGivenInSecondsDoubleInTicks) {
  const Scenario s10 = at_period("hal_sim/scenarios/seed000_realistic.toml", k10kHz_s);
  const Scenario s20 = at_period("hal_sim/scenarios/seed000_realistic_20kHz.toml", k20kHz_s);
  const firmware::DriveConfig c10 = drive_config(s10), c20 = drive_config(s20);
  // The `limited` window (four speed-loop time constants, 40 ms) and the stuck-ADC window
  // (2 ms: its evidence is volt-seconds, firmware/protection/protection_config.hpp).
  EXPECT_EQ(firmware::limited_window_ticks(c10), 400u);
  EXPECT_EQ(firmware::limited_window_ticks(c20), 800u);
  EXPECT_EQ(c10.protection.adc_stuck_ticks, 20);
  EXPECT_EQ(c20.protection.adc_stuck_ticks, 40);
  // The commissioning's 10 ms settling windows and 0.2 s square wave (docs/identification.md).
  const firmware::Nameplate plate{220.0, 3.0, 50.0, 1};
  const auto p10 = firmware::plan_identification(plate, 6.0, 311.0, k10kHz_s);
  const auto p20 = firmware::plan_identification(plate, 6.0, 311.0, k20kHz_s);
  EXPECT_EQ(p20.window_ticks, 2 * p10.window_ticks);
  EXPECT_EQ(p20.hf_ticks, 2 * p10.hf_ticks);
  // Paper 001's law on its T0 = 1 ms: 20 ticks per step instead of 10, the same law.
  const Scenario i10 = at_period("hal_sim/scenarios/seed001_realistic.toml", k10kHz_s);
  const Scenario i20 = at_period("hal_sim/scenarios/seed001_realistic_20kHz.toml", k20kHz_s);
  const firmware::IolStage<double> iol10(i10.motor, drive_config(i10),
                                         control::discretize_voltage_fed(i10.motor, k10kHz_s));
  const firmware::IolStage<double> iol20(i20.motor, drive_config(i20),
                                         control::discretize_voltage_fed(i20.motor, k20kHz_s));
  EXPECT_EQ(iol10.ticks_per_period(), 10);
  EXPECT_EQ(iol20.ticks_per_period(), 20);
  EXPECT_DOUBLE_EQ(iol20.coefficients().flux_decay, iol10.coefficients().flux_decay);
}

/// The frames of one message the drive sent over a run.
int frames_sent(const Scenario& s, firmware::protocol::MessageId id) {
  int count = 0;
  const uint16_t can_id = firmware::protocol::can_id(uint8_t(s.can_node_id), id);
  run_scenario(s, {{}, {}, [&](double, const hal::CanFrame& f) { count += f.id == can_id; }});
  return count;
}

TEST(DriveAt20kHz, TelemetryKeepsItsRate) {
  // 100 Hz fast telemetry is every 100 ticks at 10 kHz, every 200 at 20 kHz: over 1 s the
  // same count (a boundary frame may fall on either side of the end: +-1).
  using firmware::protocol::MessageId;
  const char* file = "hal_sim/scenarios/seed000_realistic.toml";
  const int n10 = frames_sent(at_period(file, k10kHz_s, {"simulation.duration_s=1"}),
                              MessageId::telemetry_speed_flux);
  const int n20 = frames_sent(at_period(file, k20kHz_s, {"simulation.duration_s=1"}),
                              MessageId::telemetry_speed_flux);
  EXPECT_NEAR(n10, 100, 1);
  EXPECT_NEAR(n20, n10, 1);
}

/// The detection latency of one injected fault.
double latency_s(Scenario s, FaultKind kind, double at_s) {
  FaultInjection f;
  f.kind = kind;
  f.at_s = at_s;
  s.faults = {f};
  s.duration_s = at_s + 0.4;
  const Summary r = run_scenario(s);
  EXPECT_FALSE(r.faults.empty()) << fault_kind_name(kind);
  return r.faults.empty() ? NAN : r.faults.front().detected_at_s - r.faults.front().injected_at_s;
}

TEST(DriveAt20kHz, ProtectionsAnswerInTheSameTime) {
  // The windows are times, so the detection latency in seconds is the same at both rates up
  // to where each rate's ticks fall: one 10 kHz tick plus one 20 kHz tick.
  const double tolerance_s = k10kHz_s + k20kHz_s;
  const char* realistic = "hal_sim/scenarios/seed000_realistic.toml";
  // Stuck ADC at 100 rad/s, 1 N m (the fault matrix's point): 20 ticks at 10 kHz.
  const double stuck10 = latency_s(at_period(realistic, k10kHz_s), FaultKind::adc_stuck, 1.0);
  const double stuck20 = latency_s(at_period(realistic, k20kHz_s), FaultKind::adc_stuck, 1.0);
  // The command watchdog's 0.2 s after the last set_speed (seed000_can.toml's every 50 ms).
  const char* can = "hal_sim/scenarios/seed000_can.toml";
  const double silence10 = latency_s(at_period(can, k10kHz_s), FaultKind::can_silence, 0.4);
  const double silence20 = latency_s(at_period(can, k20kHz_s), FaultKind::can_silence, 0.4);
  std::printf("stuck ADC %.2f / %.2f ms, CAN silence %.2f / %.2f ms at 10 / 20 kHz\n",
              stuck10 * 1e3, stuck20 * 1e3, silence10 * 1e3, silence20 * 1e3);
  EXPECT_NEAR(stuck20, stuck10, tolerance_s);
  EXPECT_NEAR(silence20, silence10, tolerance_s);
}

}  // namespace
}  // namespace imd::sim
