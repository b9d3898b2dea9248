// The fault matrix: every fault the simulated board can suffer, injected into a running drive.
// Each must be detected with its own code within its bound, turn the PWM off in the tick that
// detects it, and stay latched to the end of the run (docs/safety.md has the table).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <cstdio>
#include <string>

#include "control/encoder_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_state.hpp"
#include "hal_sim/scenario.hpp"
#include "hal_sim/drive/scenario_run.hpp"

namespace imd::sim {
namespace {

constexpr double kTick_s = 1e-4;

Scenario base(const char* file) {
  return load_scenario(std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/" + file,
                       {"simulation.duration_s=1.4"});
}

struct Case {
  FaultInjection fault;
  const char* code;
  double bound_s;  ///< detection latency bound
  /// The stop it takes (docs/safety.md, "Stop categories"), and how long the PWM may stay on
  /// after detection for it: 0 for STO.
  const char* stop = "sto";
  double stop_bound_s = 0.0;
};

/// Runs the scenario with one fault and checks the event; returns the detection latency.
double run_case(Scenario s, const Case& c) {
  s.faults = {c.fault};
  int state_after = -1;
  bool left_fault_state = false;
  const Summary r =
      run_scenario(s, {[&](const SimRow& row) {
                         if (state_after >= 0 && row.state != int(firmware::DriveState::fault)) {
                           left_fault_state = true;
                         }
                         if (row.state == int(firmware::DriveState::fault)) {
                           state_after = row.state;
                         }
                       },
                       {},
                       {}});
  EXPECT_EQ(r.faults.size(), 1u) << fault_kind_name(c.fault.kind);
  if (r.faults.empty()) return NAN;
  const FaultEvent& f = r.faults.front();
  EXPECT_EQ(f.code, c.code);
  EXPECT_EQ(f.injected, fault_kind_name(c.fault.kind));
  EXPECT_DOUBLE_EQ(f.injected_at_s, std::ceil(c.fault.at_s / kTick_s - 1e-9) * kTick_s);
  const double latency_s = f.detected_at_s - f.injected_at_s;
  EXPECT_GE(latency_s, 0.0);
  EXPECT_LE(latency_s, c.bound_s + 1e-9) << c.code;
  EXPECT_EQ(f.stop, c.stop) << c.code;
  if (c.stop_bound_s == 0.0) {
    EXPECT_EQ(f.pwm_off_at_s, f.detected_at_s) << "the PWM must go off in the detecting tick";
  } else {  // a controlled stop first, time-limited
    EXPECT_GT(f.pwm_off_at_s, f.detected_at_s) << c.code;
    EXPECT_LE(f.pwm_off_at_s - f.detected_at_s, c.stop_bound_s + 1e-9) << c.code;
  }
  EXPECT_FALSE(left_fault_state) << "latched until cleared";
  std::printf(
      "fault matrix: %-12s -> %-16s injected %.4f s, detected %.4f s (+%.1f ms), PWM off "
      "%.4f s\n",
      fault_kind_name(c.fault.kind), f.code.c_str(), f.injected_at_s, f.detected_at_s,
      latency_s * 1e3, f.pwm_off_at_s);
  return latency_s;
}

FaultInjection at(double at_s, FaultKind kind) {
  FaultInjection f;
  f.at_s = at_s;
  f.kind = kind;
  return f;
}

// The realistic paper-000 board at t = 1 s: speed 100 rad/s (the sine's crest), 1 N m load.
constexpr double kInject_s = 1.0;

TEST(FaultMatrix, Overcurrent) {
  FaultInjection f = at(kInject_s, FaultKind::overcurrent);
  f.surge_A = 20.0;  // past the 9 A trip (1.5 i_max)
  f.phase = 1;
  EXPECT_EQ(run_case(base("seed000_realistic.toml"), {f, "overcurrent", kTick_s}), 0.0);
}

TEST(FaultMatrix, Overvoltage) {
  FaultInjection f = at(kInject_s, FaultKind::overvoltage);
  f.bus_V = 450.0;  // past 1.3 x 311 V
  EXPECT_EQ(run_case(base("seed000_realistic.toml"), {f, "bus_overvoltage", kTick_s}), 0.0);
}

TEST(FaultMatrix, Undervoltage) {
  FaultInjection f = at(kInject_s, FaultKind::undervoltage);
  f.bus_V = 150.0;  // below 0.7 x 311 V
  EXPECT_EQ(run_case(base("seed000_realistic.toml"), {f, "bus_undervoltage", kTick_s}), 0.0);
}

TEST(FaultMatrix, EncoderLoss) {
  // At 100 rad/s: DC braking at the current limit, for the time the braking torque takes to
  // stop the rotor from there without load plus three rotor time constants
  // (firmware/stages/dc_brake.hpp): 0.19 + 0.12 s.
  run_case(base("seed000_realistic.toml"),
           {at(kInject_s, FaultKind::encoder_loss), "encoder", 0.01, "dc_brake", 0.32});
}

TEST(FaultMatrix, EncoderLossAtLowSpeed) {
  // At the sine's zero crossing (t = 2 s, 0 rad/s, accelerating at 157 rad/s^2: 1.6 N m). The
  // check (firmware/protection/encoder_check.hpp) allows any load up to L_max = 3/4 of the
  // torque at the current limit (3.4 N m at this flux): motion is proven only once the drive's
  // torque exceeds L_max. The bound assumes the law reaches its full torque within four of its
  // speed loop's time constants (40 ms, the `limited` window) while the worst load brakes the
  // lower speed bound at L_max / J; then the bound climbs at (T_cap - L_max) / J until it has
  // travelled 2 counts.
  Scenario s = base("seed000_realistic.toml");
  s.duration_s = 2.5;
  const control::MotorParameters& m = s.motor;
  const double q = 2 * std::numbers::pi / s.encoder_cpr;
  const double flux = std::sqrt(0.2), i_lim = 0.95 * s.i_max_A;
  const double t_cap = 1.5 * m.pole_pairs * m.Lm_H / m.Lr_H * flux *
                       std::sqrt(i_lim * i_lim - std::pow(flux / m.Lm_H, 2));
  const double l_max = 0.75 * t_cap;
  const auto e = control::encoder_quantization_bounds(
      control::discretize_voltage_fed(m, s.sample_period_s), s.encoder_bandwidth_rad_s, q);
  // The check's margin at the last count: the quantization error and the observer's lag
  // after a load step of 2 L_max (from one end of the bound to the other).
  double omega = -(e.omega_rad_s + 2 * l_max / (m.J_kgm2 * s.encoder_bandwidth_rad_s)), x = 0.0;
  double t = 0.0;
  const double t_full = 4.0 / 100.0;  // the speed loop's 100 rad/s (control/ifoc_design.hpp)
  for (; x <= 2 * q && t < 1.0; t += kTick_s) {
    const double a = (t < t_full ? -l_max : t_cap - l_max) / m.J_kgm2;
    x += std::min(omega, omega + a * kTick_s) * kTick_s;
    omega += a * kTick_s;
  }
  std::printf("encoder loss at low speed: bound %.1f ms (L_max %.2f N m of %.2f)\n", t * 1e3,
              l_max, t_cap);
  // Detected at low speed: nothing to brake by DC injection, STO.
  run_case(s, {at(2.0, FaultKind::encoder_loss), "encoder", t + kTick_s});
}

TEST(FaultMatrix, AdcStuck) {
  // 20 identical ticks, and the voltage must have moved the current by four codes.
  run_case(base("seed000_realistic.toml"),
           {at(kInject_s, FaultKind::adc_stuck), "adc_stuck", 0.01});
}

TEST(FaultMatrix, PhaseLoss) {
  // Judged over windows of the transient time constant (25 ticks): found in the first full
  // window once the law wants current in the phase, at most a sixth of an electrical
  // revolution after its zero crossing (10 ms at 100 rad/s, one pole pair): 15 ms.
  FaultInjection f = at(kInject_s, FaultKind::phase_loss);
  f.phase = 2;
  run_case(base("seed000_realistic.toml"), {f, "phase_loss", 0.015});
}

TEST(FaultMatrix, Overrun) {
  // The tick budget is 100 ms of host time: a tick of the lock-step run takes microseconds, and
  // even a loaded 2-core machine does not deschedule it for that long (10 ms happened), while
  // the injected stall of 250 ms always overruns it.
  Scenario s = base("seed000_realistic.toml");
  s.protection.tick_budget_us = 100'000.0;
  FaultInjection f = at(kInject_s, FaultKind::overrun);
  f.stall_us = 250'000.0;
  EXPECT_EQ(run_case(s, {f, "overrun", kTick_s}), 0.0);
}

TEST(FaultMatrix, CanSilence) {
  // seed000_can.toml repeats set_speed every 50 ms with a 0.2 s watchdog: the trip comes 0.2 s
  // plus one tick after the last frame, which precedes the silence. SS1: the speed ramps from
  // 50 rad/s at the stop deceleration (200 rad/s^2, 0.25 s), then STO; 0.1 s more for the
  // speed loop to bring the rotor below the stop speed.
  Scenario s = base("seed000_can.toml");
  const double timeout_s = *s.protection.command_timeout_s;
  run_case(s, {at(0.4, FaultKind::can_silence), "command_timeout", timeout_s + kTick_s, "ss1",
               50.0 / 200.0 + 0.1});
}

}  // namespace
}  // namespace imd::sim
