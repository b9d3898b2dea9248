// The protect stage on hand-made measurements and estimates: which faults trip, in which
// order the first is named, what is judged only while the inverter drives the motor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "control/frames.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/protection/protection.hpp"
#include "paper_motor.hpp"

namespace imd::firmware {
namespace {

using Vec2 = control::Vec2<double>;

/// The protect stage with the checks of a motor model (the drive passes them each tick).
struct MotorProtection {
  Protection<double> protection;
  MotorChecks<double> motor;
  Trip check(const Measurement<double>& m, const Estimate<double>& e, const SupervisedState& s,
             const LawOutput<double>& law, const Modulation<double>& out) {
    return protection.check(m, e, s, law, out, &motor);
  }
  void set_clock(uint32_t clock_Hz) { protection.set_clock(clock_Hz); }
  Trip over_budget(uint32_t counts) const { return protection.over_budget(counts); }
};

struct Bench {
  DriveConfig config;
  Measurement<double> m;
  Estimate<double> e;
  SupervisedState s;
  LawOutput<double> law;
  Modulation<double> out;

  Bench() {
    config.protection.overcurrent_A = 9.0;
    config.protection.bus_min_V = 200.0;
    config.protection.bus_max_V = 450.0;
    config.protection.overspeed_rad_s = 400.0;
    m.valid = true;
    m.v_bus_V = 311.0;
    m.i_abc_A[0] = 1.0, m.i_abc_A[1] = -0.5, m.i_abc_A[2] = -0.5;
    m.i_peak_A = 1.0;
    e.valid = true;
    e.x.flux_r_AB_Wb = Vec2(0.45, 0.0);
    s.modulating = true;
  }
  MotorProtection make() const {
    return {Protection<double>(config),
            MotorChecks<double>(test::paper_motor(),
                                control::discretize_voltage_fed(test::paper_motor(),
                                                                config.sample_period_s),
                                config, 8192.0, 10.0 / 2048)};
  }
};

TEST(Protection, AHealthyTickTripsNothing) {
  Bench b;
  MotorProtection p = b.make();
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
}

TEST(Protection, TheFirstFaultIsNamedAndEveryFaultIsCounted) {
  Bench b;
  MotorProtection p = b.make();
  b.m.i_abc_A[1] = -9.5;  // phase b past the 9 A trip
  b.m.i_peak_A = 9.5;
  b.m.v_bus_V = 500.0;
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out);
  EXPECT_EQ(t.first, FaultCode::overcurrent);
  EXPECT_EQ(t.detail, 1);  // the phase
  EXPECT_EQ(t.bits, (1u << unsigned(FaultCode::overcurrent)) |
                        (1u << unsigned(FaultCode::bus_overvoltage)));
}

TEST(Protection, ARailCodeIsOvercurrent) {
  Bench b;
  MotorProtection p = b.make();
  b.m.adc_saturated = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::overcurrent);
}

TEST(Protection, UndervoltageIsJudgedOnlyWhileDriving) {
  Bench b;
  MotorProtection p = b.make();
  b.m.v_bus_V = 150.0;
  b.s.modulating = false;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
  b.s.modulating = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::bus_undervoltage);
  b.m.v_bus_V = std::numeric_limits<double>::quiet_NaN();  // a NaN reading is no bus
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::bus_undervoltage);
}

TEST(Protection, TheEnableInputMattersOnlyWhileDriving) {
  Bench b;
  MotorProtection p = b.make();
  b.s.enable_input = false;
  b.s.modulating = false;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
  b.s.modulating = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::enable_input);
}

TEST(Protection, WhileCalibratingOnlyTheOffsetIsJudged) {
  Bench b;
  MotorProtection p = b.make();
  b.m.valid = false;
  b.m.i_peak_A = 100.0;  // not a measurement: ignored
  b.m.calibration = Calibration::offset_fault;
  b.m.offset_fault_phase = 2;
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out);
  EXPECT_EQ(t.first, FaultCode::adc_offset);
  EXPECT_EQ(t.detail, 2);
  EXPECT_EQ(t.bits, 1u << unsigned(FaultCode::adc_offset));
}

TEST(Protection, MagnetizingTimesOutAfterTwiceTheRotorsMagnetizingTimeOrTheFloor) {
  // The paper-000 motor: tau_r = Lr/Rr = 40.9 ms; under the current that holds the reference
  // the squared flux reaches 0.95 of it in tau_r ln(1 / (1 - sqrt 0.95)) = 3.68 tau_r, 150 ms;
  // twice that is 3 005 ticks at 100 us, below the 2 s floor. A floor of 0.1 s lets the
  // motor's own time through.
  const control::MotorParameters m = test::paper_motor();
  const double derived_s = 2 * m.Lr_H / m.Rr_Ohm * std::log(1 / (1 - std::sqrt(0.95)));
  for (const double floor_s : {2.0, 0.1}) {
    Bench b;
    b.config.magnetizing_timeout_s = floor_s;
    MotorProtection p = b.make();
    const auto ticks = uint32_t(std::ceil(std::max(floor_s, derived_s) / 1e-4));
    EXPECT_EQ(p.motor.magnetizing_timeout_ticks, ticks) << floor_s;
    b.s.magnetizing = true;
    b.s.magnetizing_ticks = ticks;
    EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
    b.s.magnetizing_ticks = ticks + 1;
    EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::magnetizing_timeout);
  }
}

TEST(Protection, ALawWithoutSolutionTripsAfterItsWindowAndANonFiniteOutputAtOnce) {
  Bench b;
  MotorProtection p = b.make();
  // The paper-000 motor at 100 us: the phase-loss window is its transient time constant,
  // ceil(1 / (gamma T)) = 25 ticks, longer than the stuck-ADC check's 20: two of them.
  const uint32_t window = p.motor.law_failure.window_ticks();
  EXPECT_EQ(window, 2u * p.motor.phase_loss.window_ticks());
  EXPECT_EQ(p.motor.phase_loss.window_ticks(), 25u);
  b.law.ok = false;
  for (uint32_t k = 1; k < window; ++k) {
    ASSERT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any()) << k;
  }
  // One solution in between starts the count again.
  b.law.ok = true;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
  b.law.ok = false;
  for (uint32_t k = 1; k < window; ++k) {
    ASSERT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any()) << k;
  }
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out);
  EXPECT_EQ(t.first, FaultCode::singular_control);
  // A non-finite output trips in its own tick, beside it.
  b.out.finite = false;
  const Trip both = p.check(b.m, b.e, b.s, b.law, b.out);
  EXPECT_EQ(both.bits, (1u << unsigned(FaultCode::singular_control)) |
                           (1u << unsigned(FaultCode::non_finite)));
  b.law.ok = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::non_finite);
}

TEST(Protection, TheCommandWatchdogNeedsCanCommands) {
  Bench b;
  b.config.protection.command_timeout_s = 0.01;  // 100 ticks
  b.s.watchdog_armed = true;
  b.s.command_silence_ticks = 101;
  MotorProtection local = b.make();
  EXPECT_FALSE(local.check(b.m, b.e, b.s, b.law, b.out).any());
  b.config.commands_over_can = true;
  MotorProtection commanded = b.make();
  EXPECT_EQ(commanded.check(b.m, b.e, b.s, b.law, b.out).first,
            FaultCode::command_timeout);
}

TEST(Protection, TheBudgetIsInCountsOfTheExecutionClock) {
  Bench b;
  b.config.protection.tick_budget_ns = 90'000;
  MotorProtection p = b.make();
  p.set_clock(25'000'000);  // 40 ns per count: 2250 counts
  EXPECT_FALSE(p.over_budget(2250).any());
  EXPECT_EQ(p.over_budget(2251).first, FaultCode::overrun);
  b.config.protection.tick_budget_ns = 0;  // not checked
  MotorProtection unchecked = b.make();
  unchecked.set_clock(25'000'000);
  EXPECT_FALSE(unchecked.over_budget(UINT32_MAX).any());
}

TEST(Protection, TheSensorChecksCanBeSwitchedOff) {
  Bench b;
  b.config.protection.check_encoder = false;
  MotorProtection p = b.make();
  b.m.encoder_delta_counts = 100000;  // an impossible jump
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out).any());
  b.config.protection.check_encoder = true;
  MotorProtection checked = b.make();
  EXPECT_EQ(checked.check(b.m, b.e, b.s, b.law, b.out).first, FaultCode::encoder);
}

/// The phase-loss check's window on the paper motor: the check's own rule
/// (firmware/protection/protection.cpp), in the design arithmetic.
int phase_loss_window_ticks(const DriveConfig& config) {
  const control::VoltageFedConstants k = control::derive_voltage_fed(test::paper_motor());
  return int(std::max(std::ceil(Real(1) / (k.gamma_per_s * config.sample_period_s)), Real(4)));
}

// A converter that freezes: its codes repeat while the model predicts the current moving on.
// The frozen reading also looks like phases that stopped carrying current. Here the codes
// freeze as a phase-loss window opens, with phase a's current near zero, and the model's
// prediction holds still for the stuck check's first window (no evidence: it restarts); the
// phase-loss window would end first and blame phase a. It must wait while the codes repeat, so
// that the stuck check names the fault once the prediction moves (turning by 0.1 rad a tick,
// judged a half window after its first window).
TEST(Protection, FrozenCodesAreAStuckAdcNotALostPhase) {
  Bench b;
  MotorProtection p = b.make();
  const int window = phase_loss_window_ticks(b.config);
  const int stuck_ticks = b.config.protection.adc_stuck_ticks;
  ASSERT_GT(window, stuck_ticks) << "the case needs the phase-loss window to end in the freeze";
  ASSERT_LT(window, 2 * stuck_ticks) << "and before the stuck check's second window ends";
  const double amplitude_A = 3.0, step_rad = 0.1, pi = std::acos(-1.0);
  const int freeze = window + 1;  // the first call is skipped: a window ends at the freeze
  auto current = [&](int tick) {
    const double angle = pi / 2 + step_rad * (tick - freeze + 1);  // phase a at zero then
    return Vec2(amplitude_A * std::cos(angle), amplitude_A * std::sin(angle));
  };
  Trip first;
  int tick = 0;
  for (; tick < freeze + 2 * stuck_ticks && !first.any(); ++tick) {
    const bool frozen = tick >= freeze;
    b.e.current_predicted = true;
    // The model: the measured current until the freeze, then still at the last one read for
    // a window, then on.
    const int still_until = freeze + stuck_ticks;
    b.e.i_predicted_alphabeta_A = current(
        tick < freeze ? tick : tick < still_until ? freeze - 1 : freeze + (tick - still_until));
    if (!frozen) {
      const control::PhaseValues<double> abc = control::inverse_clarke(current(tick));
      for (int j = 0; j < 3; ++j) {
        b.m.i_abc_A[j] = abc[j];
        b.m.phase_code[std::size_t(j)] = uint16_t(2048 + std::lround(abc[j] / (10.0 / 2048)));
      }
    }
    first = p.check(b.m, b.e, b.s, b.law, b.out);
    if (!frozen) {
      ASSERT_FALSE(first.any()) << "healthy tick " << tick;
    }
  }
  ASSERT_TRUE(first.any()) << "the frozen converter went unnoticed";
  EXPECT_EQ(first.first, FaultCode::adc_stuck);
  // The windows slide by halves of stuck_ticks / 2 repeated ticks from the freeze: the first
  // judgement (at the end of the second half) sees two still halves; the next, a half later,
  // the first turning half against a still one. tick counts the calls, one more.
  EXPECT_EQ(tick, freeze + 3 * stuck_ticks / 2) << "a half after the first window";
}

// The other side of the wait: an open phase at standstill under a held voltage, read by a
// quiet ADC, freezes the codes too, and gives the stuck check no evidence (a still
// prediction). The phase-loss check waits one stuck-ADC window at most, then judges the frozen
// ticks: the open phase is found within that window, the phase-loss window and the first
// skipped tick.
TEST(Protection, AnOpenPhaseUnderAStillVoltageIsFoundThoughTheCodesRepeat) {
  Bench b;
  MotorProtection p = b.make();
  const int window_ticks = phase_loss_window_ticks(b.config);
  const int stuck_ticks = b.config.protection.adc_stuck_ticks;
  b.e.current_predicted = true;
  b.e.i_predicted_alphabeta_A = Vec2(3.0, 0.0);  // the model: 3 A in phase a, -1.5 A in b, c
  b.m.i_abc_A[0] = 0.0, b.m.i_abc_A[1] = 2.6, b.m.i_abc_A[2] = -2.6;  // a open: b to c only
  b.m.phase_code = {2048, uint16_t(2048 + 532), uint16_t(2048 - 532)};  // 10 A / 2048 codes
  b.m.i_peak_A = 2.6;
  Trip first;
  int tick = 0;
  for (; tick < 10 * (stuck_ticks + window_ticks) && !first.any(); ++tick) {
    first = p.check(b.m, b.e, b.s, b.law, b.out);
  }
  ASSERT_TRUE(first.any()) << "the open phase went unnoticed for " << tick << " ticks";
  EXPECT_EQ(first.first, FaultCode::phase_loss);
  EXPECT_EQ(first.detail, 0) << "phase a";
  EXPECT_LE(tick, stuck_ticks + window_ticks + 1);
}

}  // namespace
}  // namespace imd::firmware
