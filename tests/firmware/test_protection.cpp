// The protect stage on hand-made measurements and estimates: which faults trip, in which
// order the first is named, what is judged only while the inverter drives the motor.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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
             const LawOutput<double>& law, const Modulation<double>& out, const Vec2& u_last_V) {
    return protection.check(m, e, s, law, out, u_last_V, &motor);
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
    config.magnetizing_timeout_s = 0.01;  // 100 ticks
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
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
}

TEST(Protection, TheFirstFaultIsNamedAndEveryFaultIsCounted) {
  Bench b;
  MotorProtection p = b.make();
  b.m.i_abc_A[1] = -9.5;  // phase b past the 9 A trip
  b.m.i_peak_A = 9.5;
  b.m.v_bus_V = 500.0;
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero());
  EXPECT_EQ(t.first, FaultCode::overcurrent);
  EXPECT_EQ(t.detail, 1);  // the phase
  EXPECT_EQ(t.bits, (1u << unsigned(FaultCode::overcurrent)) |
                        (1u << unsigned(FaultCode::bus_overvoltage)));
}

TEST(Protection, ARailCodeIsOvercurrent) {
  Bench b;
  MotorProtection p = b.make();
  b.m.adc_saturated = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first, FaultCode::overcurrent);
}

TEST(Protection, UndervoltageIsJudgedOnlyWhileDriving) {
  Bench b;
  MotorProtection p = b.make();
  b.m.v_bus_V = 150.0;
  b.s.modulating = false;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
  b.s.modulating = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first, FaultCode::bus_undervoltage);
  b.m.v_bus_V = std::numeric_limits<double>::quiet_NaN();  // a NaN reading is no bus
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first, FaultCode::bus_undervoltage);
}

TEST(Protection, TheEnableInputMattersOnlyWhileDriving) {
  Bench b;
  MotorProtection p = b.make();
  b.s.enable_input = false;
  b.s.modulating = false;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
  b.s.modulating = true;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first, FaultCode::enable_input);
}

TEST(Protection, WhileCalibratingOnlyTheOffsetIsJudged) {
  Bench b;
  MotorProtection p = b.make();
  b.m.valid = false;
  b.m.i_peak_A = 100.0;  // not a measurement: ignored
  b.m.calibration = Calibration::offset_fault;
  b.m.offset_fault_phase = 2;
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero());
  EXPECT_EQ(t.first, FaultCode::adc_offset);
  EXPECT_EQ(t.detail, 2);
  EXPECT_EQ(t.bits, 1u << unsigned(FaultCode::adc_offset));
}

TEST(Protection, MagnetizingTimesOutAfterItsTicks) {
  Bench b;
  MotorProtection p = b.make();
  b.s.magnetizing = true;
  b.s.magnetizing_ticks = 100;
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
  b.s.magnetizing_ticks = 101;
  EXPECT_EQ(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first,
            FaultCode::magnetizing_timeout);
}

TEST(Protection, ALawWithoutSolutionAndANonFiniteOutputTrip) {
  Bench b;
  MotorProtection p = b.make();
  b.law.ok = false;
  b.out.finite = false;
  const Trip t = p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero());
  EXPECT_EQ(t.first, FaultCode::singular_control);
  EXPECT_EQ(t.bits, (1u << unsigned(FaultCode::singular_control)) |
                        (1u << unsigned(FaultCode::non_finite)));
}

TEST(Protection, TheCommandWatchdogNeedsCanCommands) {
  Bench b;
  b.config.protection.command_timeout_s = 0.01;  // 100 ticks
  b.s.watchdog_armed = true;
  b.s.command_silence_ticks = 101;
  MotorProtection local = b.make();
  EXPECT_FALSE(local.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
  b.config.commands_over_can = true;
  MotorProtection commanded = b.make();
  EXPECT_EQ(commanded.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first,
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
  EXPECT_FALSE(p.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).any());
  b.config.protection.check_encoder = true;
  MotorProtection checked = b.make();
  EXPECT_EQ(checked.check(b.m, b.e, b.s, b.law, b.out, Vec2::Zero()).first, FaultCode::encoder);
}

}  // namespace
}  // namespace imd::firmware
