// The protection detectors on their own: the state machine's graph, the encoder plausibility
// model, the stuck-ADC and phase-loss checks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "firmware/protection/adc_stuck_check.hpp"
#include "firmware/protection/encoder_check.hpp"
#include "firmware/protection/phase_loss_check.hpp"
#include "firmware/state_machine.hpp"

namespace imd::firmware {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(StateMachine, FollowsTheGraphAndLogsEveryTransition) {
  StateMachine m;
  EXPECT_FALSE(m.go(DriveState::running, TransitionReason::enable, 1));  // not from calibrating
  EXPECT_EQ(m.state(), DriveState::calibrating);
  EXPECT_TRUE(m.go(DriveState::idle, TransitionReason::calibrated, 2));
  EXPECT_FALSE(m.go(DriveState::running, TransitionReason::enable, 3));  // magnetize first
  EXPECT_TRUE(m.go(DriveState::magnetizing, TransitionReason::enable, 4));
  EXPECT_TRUE(m.go(DriveState::running, TransitionReason::magnetized, 5));
  EXPECT_FALSE(m.go(DriveState::idle, TransitionReason::disable, 6));  // stop first
  EXPECT_TRUE(m.go(DriveState::fault, TransitionReason::fault, 7));
  EXPECT_FALSE(m.go(DriveState::fault, TransitionReason::fault, 8));         // already latched
  EXPECT_FALSE(m.go(DriveState::magnetizing, TransitionReason::enable, 9));  // clear first
  EXPECT_TRUE(m.go(DriveState::idle, TransitionReason::clear_faults, 10));
  EXPECT_EQ(m.count(), 5u);
  EXPECT_EQ(m.entered(DriveState::idle), 2u);
  Transition t;
  ASSERT_TRUE(m.logged(3, t));
  EXPECT_EQ(t.tick, 7u);
  EXPECT_EQ(t.from, DriveState::running);
  EXPECT_EQ(t.to, DriveState::fault);
  EXPECT_FALSE(m.logged(5, t));
}

TEST(StateMachine, ShutdownLeadsFromAModulatingStateToIdleOnly) {
  StateMachine m;
  EXPECT_FALSE(m.go(DriveState::idle, TransitionReason::shutdown, 1));  // calibrating: no
  ASSERT_TRUE(m.go(DriveState::idle, TransitionReason::calibrated, 2));
  ASSERT_TRUE(m.go(DriveState::magnetizing, TransitionReason::enable, 3));
  ASSERT_TRUE(m.go(DriveState::running, TransitionReason::magnetized, 4));
  EXPECT_FALSE(m.go(DriveState::stopping, TransitionReason::shutdown, 5));  // to idle only
  EXPECT_TRUE(m.go(DriveState::idle, TransitionReason::shutdown, 6));
  ASSERT_TRUE(m.go(DriveState::fault, TransitionReason::fault, 7));
  EXPECT_FALSE(m.go(DriveState::idle, TransitionReason::shutdown, 8));  // a fault stays latched
  EXPECT_EQ(m.state(), DriveState::fault);
}

TEST(StateMachine, KeepsTheLastTransitionsWhenTheLogWraps) {
  StateMachine m;
  m.go(DriveState::idle, TransitionReason::calibrated, 0);
  for (uint64_t k = 1; k <= 40; k += 2) {
    m.go(DriveState::magnetizing, TransitionReason::enable, k);
    m.go(DriveState::idle, TransitionReason::disable, k + 1);
  }
  Transition t;
  EXPECT_FALSE(m.logged(0, t));
  ASSERT_TRUE(m.logged(m.count() - 1, t));
  EXPECT_EQ(t.tick, 40u);
  EXPECT_EQ(t.reason, TransitionReason::disable);
}

/// The paper-000 motor's inertia and an 8192-count encoder at 10 kHz.
EncoderCheck<double>::Config encoder_config() {
  return {8192.0, 1e-4, 0.01, 0.0, 4.0, 0.01, 400.0};
}
constexpr double kCountRad = 2 * kPi / 8192.0;

TEST(EncoderCheck, AWorkingEncoderAtSpeedPasses) {
  EncoderCheck<double> check(encoder_config());
  // 3 rad/s: one count every 2.6 ticks; the counts arrive as the angle crosses each step.
  double theta = 0.0;
  long last = 0;
  for (int k = 0; k < 20000; ++k) {
    theta += 3.0 * 1e-4;
    const long count = std::lround(std::floor(theta / kCountRad));
    ASSERT_FALSE(check.failed(int32_t(count - last), 3.0, 0.5, 0.5)) << k;
    last = count;
  }
}

TEST(EncoderCheck, SilenceAtSpeedFailsWithinTheMissingCounts) {
  EncoderCheck<double> check(encoder_config());
  EXPECT_FALSE(check.failed(13, 100.0, 0.0, 0.0));  // 100 rad/s = 13 counts per tick
  // Frozen: the model predicts 13 counts over the next period, more than the 4 allowed.
  EXPECT_TRUE(check.failed(0, 100.0, 0.0, 0.0));
}

TEST(EncoderCheck, AcceleratingWithoutCountsFailsWithinTenMilliseconds) {
  EncoderCheck<double> check(encoder_config());
  // From rest with 1 N m more than the load on J = 0.01: 100 rad/s^2. Four counts
  // (3.07e-3 rad) take sqrt(2 * 3.07e-3 / 100) = 7.8 ms.
  int k = 0;
  while (!check.failed(0, 0.0, 0.0, 1.0) && k < 1000) ++k;
  EXPECT_LE(k, 80);
  EXPECT_GE(k, 76);
}

TEST(EncoderCheck, AHeldRotorWithAnEstimationBiasPasses) {
  // Standstill under load: no counts for 10 s, torque = load up to a 0.5 N m bias. Within one
  // 10 ms window the bias moves the model by 0.5 * 0.01^2 / (2 * 0.01) = 2.5e-3 rad = 3.3
  // counts < 4, and the window re-anchors to the (zero) estimated speed.
  EncoderCheck<double> check(encoder_config());
  for (int k = 0; k < 100000; ++k) ASSERT_FALSE(check.failed(0, 0.0, 1.0, 1.5)) << k;
}

TEST(EncoderCheck, AStartOffByTheQuantizationErrorsPasses) {
  // A rotor held at standstill dithering across a count edge: each count re-anchors the model
  // to estimates the observer has just corrected, off by up to dw and dL (the paper motor's
  // bounds at 400 rad/s: 0.53 rad/s and 0.76 N m). The allowance grows with them; without it the
  // same start trips.
  EncoderCheck<double>::Config config = encoder_config();
  config.missing_counts = 2.0;
  config.window_s = 0.02;
  config.speed_error_rad_s = 0.53;
  config.load_error_Nm = 0.76;
  EncoderCheck<double> check(config);
  EncoderCheck<double>::Config bare = config;
  bare.speed_error_rad_s = bare.load_error_Nm = 0.0;
  EncoderCheck<double> without(bare);
  bool bare_tripped = false;
  for (int k = 0; k < 20000; ++k) {
    const int32_t delta = k % 400 == 0 ? (k % 800 == 0 ? 1 : -1) : 0;  // a count every 40 ms
    ASSERT_FALSE(check.failed(delta, 0.9 * 0.53, -0.9 * 0.76, 0.0)) << k;
    bare_tripped = bare_tripped || without.failed(delta, 0.9 * 0.53, -0.9 * 0.76, 0.0);
  }
  EXPECT_TRUE(bare_tripped);
  // And the allowance is what the class says: 2 counts, then dw t + dL t^2 / (2 J).
  EXPECT_NEAR(check.allowance_rad(100), 2 * kCountRad + 0.53 * 0.01 + 0.76 * 1e-4 / 0.02, 1e-15);
}

TEST(EncoderCheck, ABrakedStopPasses) {
  // 2 rad/s braked at 200 rad/s^2 (2 N m on J = 0.01): it stops after 1e-2 rad = 13 counts;
  // the counts stop with it, and the model's braking predicts the stop.
  EncoderCheck<double> check(encoder_config());
  double omega = 2.0, theta = 0.0;
  long last = 0;
  for (int k = 0; k < 5000; ++k) {
    const double torque = omega > 0 ? -2.0 : 0.0;
    theta += omega * 1e-4;
    omega = std::max(0.0, omega + torque / 0.01 * 1e-4);
    const long count = std::lround(std::floor(theta / kCountRad));
    ASSERT_FALSE(check.failed(int32_t(count - last), omega, 0.0, omega > 0 ? -2.0 : 0.0)) << k;
    last = count;
  }
}

TEST(EncoderCheck, AnImplausibleJumpFails) {
  EncoderCheck<double> check(encoder_config());
  // 1.5 x 400 rad/s over 1e-4 s is 0.06 rad = 78.2 counts; with 2 counts of margin for the
  // latching instant, 81 is the largest plausible step.
  EXPECT_EQ(check.max_jump_counts(), 81);
  EXPECT_FALSE(check.failed(81, 390.0, 0.0, 0.0));
  EXPECT_TRUE(check.failed(-82, 390.0, 0.0, 0.0));
}

TEST(AdcStuckCheck, RepeatedCodesWithAMovingVoltageAreStuck) {
  // A 12-bit converter over +-10 A (4.9 mA per code), sigma_H = 0.0259 H (paper motor), 1e-4 s:
  // a departure of 1 V held for one period moves the current by 3.861 mA, so four codes need
  // 5.1 V-periods. A 150 V vector turning by 0.05 rad per tick departs from its first value by
  // |sum_k 150 (e^{0.05ik} - 1)| = 1530 V-periods over 20 ticks: stuck at the end of the first
  // window, on the 21st sample (the first one is the reference).
  AdcStuckCheck<double> check(20, 1e-4, 0.0259, 10.0 / 2048);
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  int k = 0;
  bool stuck = false;
  for (double angle = 0.0; k < 200 && !stuck; ++k, angle += 0.05) {
    stuck = check.stuck(codes, {150.0 * std::cos(angle), 150.0 * std::sin(angle)});
  }
  EXPECT_TRUE(stuck);
  EXPECT_EQ(k, 21);
}

TEST(AdcStuckCheck, AQuietConverterAtAConstantVoltageIsNot) {
  AdcStuckCheck<double> check(20, 1e-4, 0.0259, 10.0 / 2048);
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  for (int k = 0; k < 10000; ++k) ASSERT_FALSE(check.stuck(codes, {40.0, 0.0}));
}

TEST(AdcStuckCheck, VoltageJitterIsNotEvidence) {
  // +-0.05 V of jitter around 40 V: within a 20-tick window the departures sum to at most
  // 20 x 0.1 V = 2 V-periods = 7.7 mA, under the 19.5 mA of four codes, whatever the pattern.
  AdcStuckCheck<double> check(20, 1e-4, 0.0259, 10.0 / 2048);
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  uint32_t lcg = 12345;
  for (int k = 0; k < 100000; ++k) {
    lcg = lcg * 1664525u + 1013904223u;
    const double jitter_V = (lcg >> 31) != 0 ? 0.05 : -0.05;
    ASSERT_FALSE(check.stuck(codes, {40.0 + jitter_V, jitter_V})) << k;
  }
}

TEST(AdcStuckCheck, ChangingCodesAreNotStuck) {
  AdcStuckCheck<double> check(20, 1e-4, 0.0259, 10.0 / 2048);
  for (int k = 0; k < 10000; ++k) {
    const std::array<uint16_t, 3> codes{uint16_t(2048 + k % 2), 2000, 2100};
    ASSERT_FALSE(check.stuck(codes, {150.0 * std::cos(k), 150.0 * std::sin(k)}));
  }
}

TEST(EncoderCheck, ClearsAfterAResetAtRest) {
  // A trip at speed, then the rotor at rest: after reset() (clear_faults) a silent encoder is
  // judged afresh, not on the stale prediction.
  EncoderCheck<double> check(encoder_config());
  EXPECT_FALSE(check.failed(13, 100.0, 0.0, 0.0));
  ASSERT_TRUE(check.failed(0, 100.0, 0.0, 0.0));
  check.reset();
  for (int k = 0; k < 1000; ++k) ASSERT_FALSE(check.failed(0, 0.0, 0.0, 0.0)) << k;
}

TEST(EncoderCheck, WithThePwmOffOnlyJumpsCount) {
  // Stopped against friction the load estimate stays at 1 N m with no torque applied: the
  // model would predict a reverse acceleration. With the PWM off it is not run.
  EncoderCheck<double> check(encoder_config());
  for (int k = 0; k < 10000; ++k) ASSERT_FALSE(check.failed(0, 0.0, 1.0, 0.0, false)) << k;
  EXPECT_TRUE(check.failed(100, 0.0, 1.0, 0.0, false));
}

/// Phase currents of amplitude 5 A at the flux angle plus a load angle.
void phase_currents(double angle, double (&i)[3]) {
  for (int p = 0; p < 3; ++p) i[p] = 5.0 * std::cos(angle + 0.6 - 2 * kPi * p / 3);
}

TEST(PhaseLossCheck, BalancedCurrentsPass) {
  PhaseLossCheck<double> check(0.3, 0.5, 10000);
  double i[3];
  for (int k = 0; k < 100000; ++k) {
    const double angle = 0.01 * k;
    phase_currents(angle, i);
    ASSERT_EQ(check.lost_phase(i, angle), -1) << k;
  }
}

TEST(PhaseLossCheck, AnOpenPhaseIsFoundWithinTwoRevolutions) {
  PhaseLossCheck<double> check(0.3, 0.5, 10000);
  double i[3];
  int lost = -1, k = 0;
  for (; k < 2000 && lost < 0; ++k) {
    const double angle = 0.01 * k;
    phase_currents(angle, i);
    i[1] = 0.0;    // phase b open...
    i[2] = -i[0];  // ...so c carries a's current back
    lost = check.lost_phase(i, angle);
  }
  EXPECT_EQ(lost, 1);
  EXPECT_LE(k, 630);  // one revolution: 629 steps of 0.01 rad after the first sample
}

TEST(PhaseLossCheck, ADirectCurrentIsNotJudged) {
  // Magnetizing at rest: phase a carries 5 A, b and c -2.5 A; with the current along b's
  // normal, b carries nothing, legitimately.
  PhaseLossCheck<double> check(0.3, 0.5, 10000);
  double i[3] = {4.33, 0.0, -4.33};
  for (int k = 0; k < 100000; ++k) ASSERT_EQ(check.lost_phase(i, 0.3), -1);
}

}  // namespace
}  // namespace imd::firmware
