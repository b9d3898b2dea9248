// The protection detectors on their own: the state machine's graph, the encoder plausibility
// model, the stuck-ADC and phase-loss checks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

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

/// The paper-000 motor's inertia, no friction, an 8192-count encoder at 10 kHz, 2 missing
/// counts, a 400 rad/s observer and no quantization error (the tests add their own).
EncoderCheck<double>::Config encoder_config() {
  return {8192.0, 1e-4, 0.01, 0.0, 2.0, 400.0, 0.0, 400.0};
}
constexpr double kCountRad = 2 * kPi / 8192.0;
constexpr double kMaxLoadNm = 2.5;  // the load bound the drive passes (3/4 of 3.4 N m)

TEST(EncoderCheck, AWorkingEncoderAtSpeedPasses) {
  EncoderCheck<double> check(encoder_config());
  // 3 rad/s: one count every 2.6 ticks; the counts arrive as the angle crosses each step.
  double theta = 0.0;
  long last = 0;
  for (int k = 0; k < 20000; ++k) {
    theta += 3.0 * 1e-4;
    const long count = std::lround(std::floor(theta / kCountRad));
    ASSERT_FALSE(check.failed(int32_t(count - last), 3.0, 0.5, kMaxLoadNm)) << k;
    last = count;
  }
}

TEST(EncoderCheck, SilenceAtSpeedFailsWithinTwoTicks) {
  EncoderCheck<double> check(encoder_config());
  // 100 rad/s = 13 counts per tick. The lower speed bound starts at 100 - 2 x 2.5/(0.01 400) =
  // 98.75 rad/s and falls by 2.5 N m / J = 250 rad/s^2: it crosses 2 counts (1.5 mrad) in the
  // first period. Frozen, the next silent tick fails.
  EXPECT_FALSE(check.failed(13, 100.0, 0.0, kMaxLoadNm));
  EXPECT_TRUE(check.failed(0, 100.0, 0.0, kMaxLoadNm));
}

TEST(EncoderCheck, FrozenAtLowSpeedFailsOnceTheTorqueExceedsTheLoadBound) {
  // Frozen at 1 rad/s. The lower speed bound starts at 1 - 2 x 2.5/(0.01 400) = -0.25 rad/s
  // (the observer's lag after a load step from -2.5 to +2.5 N m); with 0.5 N m of torque the
  // worst load brakes it at 200 rad/s^2: for the first 10 ms there is no evidence. Then the
  // speed loop pushes 3.4 N m: the rotor must gain (3.4 - 2.5)/0.01 = 90 rad/s^2 at least. The
  // bound is then at -2.25 rad/s and -12.5 mrad; it is back at zero speed after 25 ms, at
  // -40.6 mrad, and crosses +2 counts (1.5 mrad) after another sqrt(2 x 42.1e-3 / 90) = 31 ms:
  // 56 ms after the step of torque. The discrete sums add a tick or two; 58 ms bounds it.
  EncoderCheck<double> check(encoder_config());
  ASSERT_FALSE(check.failed(1, 1.0, 0.5, kMaxLoadNm));
  int k = 0;
  bool tripped = false;
  for (; k < 100 && !tripped; ++k) tripped = check.failed(0, 1.0, 0.5, kMaxLoadNm);
  EXPECT_FALSE(tripped) << "a stop by the worst load is possible: no evidence yet";
  for (k = 0; k < 2000 && !tripped; ++k) tripped = check.failed(0, 0.0, 3.4, kMaxLoadNm);
  EXPECT_TRUE(tripped);
  std::printf("frozen at 1 rad/s: failed %.1f ms after the torque reached 3.4 N m\n", k * 0.1);
  EXPECT_LE(k * 0.1, 58.0);
}

TEST(EncoderCheck, ALoadStepThatStopsTheRotorPasses) {
  // The false trip the old, estimate-based check raised: at 0.5 rad/s a load step of 2 N m
  // (within the 2.5 N m bound) stops the rotor in 2.5 ms against 0 N m of torque, and the
  // counts stop; the speed estimate lags, still saying 0.5 rad/s. No trip, however long.
  EncoderCheck<double> check(encoder_config());
  double omega = 0.5, theta = 0.0;
  long last = 0;
  for (int k = 0; k < 50000; ++k) {
    const double torque = k < 1000 ? 0.0 : 1.0;  // the speed loop answers with 1 N m
    theta += omega * 1e-4;
    omega = std::max(0.0, omega + (torque - 2.0) / 0.01 * 1e-4);
    const long count = std::lround(std::floor(theta / kCountRad));
    ASSERT_FALSE(check.failed(int32_t(count - last), 0.5, torque, kMaxLoadNm)) << k;
    last = count;
  }
}

TEST(EncoderCheck, ALoadThatReversesWithinTheBoundPasses) {
  // An overhauling load of -2.5 N m held at about 20 rad/s by -2.5 N m of torque; the load
  // steps to +2.5 N m, both ends within the bound: the rotor decelerates at 500 rad/s^2, stops
  // in 40 ms and reverses. The estimate lags a ramp of 500 rad/s^2 by 500/400 = 1.25 rad/s (a
  // first-order lag at the observer's bandwidth). Were the margin the lag of a step of L_max
  // (0.625 rad/s), the lower bound would start 0.625 rad/s above the true speed at the last
  // count before the stop, brake no harder than the rotor, and travel up to
  // (0.88 + 0.63)^2 / 1000 = 2.3 mrad past that count, beyond the 2 counts (1.5 mrad), when
  // the rotor stops late in a count: the 0.55 kW motor's IOL tripped so on a healthy encoder.
  // Fifty starting speeds put the stop at fifty places within a count.
  for (int start = 0; start < 50; ++start) {
    EncoderCheck<double> check(encoder_config());
    double omega = 20.0 + 0.002 * start, estimate = omega, theta = 0.0;
    long last = 0;
    for (int k = 0; k < 1000; ++k) {
      const double load = k < 100 ? -2.5 : 2.5, torque = -2.5;
      theta += omega * 1e-4;
      omega += (torque - load) / 0.01 * 1e-4;
      estimate += 400.0 * 1e-4 * (omega - estimate);
      const long count = std::lround(std::floor(theta / kCountRad));
      ASSERT_FALSE(check.failed(int32_t(count - last), estimate, torque, kMaxLoadNm))
          << "start " << omega << " rad/s, tick " << k;
      last = count;
    }
    EXPECT_LT(omega, -20.0);  // it did reverse
  }
}

TEST(EncoderCheck, AHeldRotorPasses) {
  // Standstill for 10 s, held by a load just under the bound against the drive's torque.
  EncoderCheck<double> check(encoder_config());
  for (int k = 0; k < 100000; ++k) ASSERT_FALSE(check.failed(0, 0.0, 2.4, kMaxLoadNm)) << k;
}

TEST(EncoderCheck, AStartOffByTheQuantizationErrorPasses) {
  // A rotor at standstill dithering across a count edge, each count re-anchoring the bounds at
  // an estimate off by up to dw (0.53 rad/s, the paper motor's bound at 400 rad/s), 0.4 N m of
  // torque held by a load under the 0.5 N m bound. With the error in the margin no trip;
  // without it the lower bound starts at 0.477 - 0.25 = 0.23 rad/s, brakes at only 10 rad/s^2
  // and travels 2.6 mrad (3.4 counts): the same start trips.
  EncoderCheck<double>::Config config = encoder_config();
  config.speed_error_rad_s = 0.53;
  EncoderCheck<double> check(config);
  EncoderCheck<double> without(encoder_config());
  bool bare_tripped = false;
  for (int k = 0; k < 20000; ++k) {
    const int32_t delta = k % 400 == 0 ? (k % 800 == 0 ? 1 : -1) : 0;  // a count every 40 ms
    ASSERT_FALSE(check.failed(delta, 0.9 * 0.53, 0.4, 0.5)) << k;
    bare_tripped = bare_tripped || without.failed(delta, 0.9 * 0.53, 0.4, 0.5);
  }
  EXPECT_TRUE(bare_tripped);
}

TEST(EncoderCheck, ABrakedStopPasses) {
  // 2 rad/s braked at 200 rad/s^2 (2 N m on J = 0.01): it stops after 1e-2 rad = 13 counts;
  // the counts stop with it; the braking torque is within the bounds.
  EncoderCheck<double> check(encoder_config());
  double omega = 2.0, theta = 0.0;
  long last = 0;
  for (int k = 0; k < 5000; ++k) {
    const double torque = omega > 0 ? -2.0 : 0.0;
    theta += omega * 1e-4;
    omega = std::max(0.0, omega + torque / 0.01 * 1e-4);
    const long count = std::lround(std::floor(theta / kCountRad));
    ASSERT_FALSE(check.failed(int32_t(count - last), omega, torque, kMaxLoadNm)) << k;
    last = count;
  }
}

TEST(EncoderCheck, AnImplausibleJumpFails) {
  EncoderCheck<double> check(encoder_config());
  // 1.5 x 400 rad/s over 1e-4 s is 0.06 rad = 78.2 counts; with 2 counts of margin for the
  // latching instant, 81 is the largest plausible step.
  EXPECT_EQ(check.max_jump_counts(), 81);
  EXPECT_FALSE(check.failed(81, 390.0, 0.0, kMaxLoadNm));
  EXPECT_TRUE(check.failed(-82, 390.0, 0.0, kMaxLoadNm));
}

TEST(EncoderCheck, ClearsAfterAResetAtRest) {
  // A trip at speed, then the rotor at rest: after reset() (clear_faults) a silent encoder is
  // judged afresh, not on the stale bounds.
  EncoderCheck<double> check(encoder_config());
  EXPECT_FALSE(check.failed(13, 100.0, 0.0, kMaxLoadNm));
  ASSERT_TRUE(check.failed(0, 100.0, 0.0, kMaxLoadNm));
  check.reset();
  for (int k = 0; k < 1000; ++k) ASSERT_FALSE(check.failed(0, 0.0, 0.0, kMaxLoadNm)) << k;
}

TEST(EncoderCheck, WithThePwmOffOnlyJumpsCount) {
  // The PWM off: a braked, held or coasting rotor, nothing bounds the load. Only jumps.
  EncoderCheck<double> check(encoder_config());
  for (int k = 0; k < 10000; ++k) ASSERT_FALSE(check.failed(0, 50.0, 0.0, 0.0, false)) << k;
  EXPECT_TRUE(check.failed(100, 0.0, 0.0, 0.0, false));
}

/// Phase currents of amplitude 5 A at the flux angle plus a load angle.
void phase_currents(double angle, double (&i)[3]) {
  for (int p = 0; p < 3; ++p) i[p] = 5.0 * std::cos(angle + 0.6 - 2 * kPi * p / 3);
}

/// The check as the paper-000 motor's board gives it: a 25-tick window, 0.016 A of shortfall
/// per tick allowed for the inverter's voltage error on a 311 V bus, 0.033 A for the noise, and
/// an open phase's mean |i| at most 3 x its 0.02 A of noise (four codes) and two codes more.
PhaseLossCheck<double>::Config phase_loss_config() {
  PhaseLossCheck<double>::Config c;
  c.window_ticks = 25;
  c.missing_A_per_bus_V = 0.016 / 311.0;
  c.noise_floor_A = 0.033;
  c.open_mean_A = 0.07;
  return c;
}

TEST(PhaseLossCheck, AHealthyMotorPassesAtAnySpeedAndAtRest) {
  // Prediction and measurement of a healthy motor differ by the noise of two ADC samples
  // (0.02 A rms each, four codes of the board's ADC: the noise the check's floor allows for)
  // and a systematic voltage error of 3 V (below the 5 % of 180 V allowed). At rest the current
  // is direct, along b's normal, so b carries nothing (legitimately, and the model agrees).
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  const double error_A = 3.0 * 1e-4 / 0.0557;  // 3 V over the leakage inductance, one tick
  for (const double step_rad : {0.0, 1e-4, 0.01, 0.1}) {
    PhaseLossCheck<double> check(phase_loss_config());
    for (int k = 0; k < 100000; ++k) {
      double truth[3], predicted[3], measured[3];
      phase_currents(step_rad * k + (step_rad == 0.0 ? kPi / 2 - 0.6 : 0.0), truth);
      for (int p = 0; p < 3; ++p) {
        predicted[p] = truth[p] + noise(rng) + error_A;
        measured[p] = truth[p] + noise(rng);
      }
      ASSERT_EQ(check.lost_phase(predicted, measured, 311.0), -1) << step_rad << " " << k;
    }
  }
}

TEST(PhaseLossCheck, AnOpenPhaseIsFoundInOneWindow) {
  // Phase b open: it carries nothing while the model, from the last measured current and the
  // voltage the law applied, says 0.1 A should have flowed in it this tick (a law asking little
  // of it: the voltage-limited law drives 0.29 A per tick). a and c carry what was predicted.
  PhaseLossCheck<double> check(phase_loss_config());
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  int lost = -1, k = 0;
  for (; k < 1000 && lost < 0; ++k) {
    double truth[3], predicted[3], measured[3];
    phase_currents(0.01 * k, truth);
    truth[2] = -truth[0];  // c carries a's current back
    for (int p = 0; p < 3; ++p) {
      predicted[p] = truth[p] + noise(rng);
      measured[p] = truth[p] + noise(rng);
    }
    predicted[1] = 0.1 + noise(rng);
    measured[1] = noise(rng);
    lost = check.lost_phase(predicted, measured, 311.0);
  }
  EXPECT_EQ(lost, 1);
  EXPECT_EQ(k, 1 + 25);  // the first tick after the PWM came on is skipped, then one window
}

TEST(PhaseLossCheck, TheFirstTickAfterThePwmWasOffIsNotJudged) {
  // Its prediction took the open terminals of a PWM-off period for zero volts: a motor turning
  // at speed would show a whole tick's back-EMF worth of shortfall that is not there.
  PhaseLossCheck<double> check(phase_loss_config());
  for (int round = 0; round < 3; ++round) {
    check.idle();
    const double wrong[3] = {50.0, -25.0, -25.0}, zero[3] = {0.0, 0.0, 0.0};
    EXPECT_EQ(check.lost_phase(wrong, zero, 311.0), -1);
    for (int k = 0; k < 25; ++k) {
      const double healthy[3] = {0.5, -0.25, -0.25};  // little: the wrong tick would weigh
      ASSERT_EQ(check.lost_phase(healthy, healthy, 311.0), -1) << k;
    }
  }
}

TEST(PhaseLossCheck, AShortfallWithinTheBoundsIsNotALoss) {
  // The sums' arithmetic at the edge: a phase carrying nothing while the prediction says 0.04 A
  // (below the 0.049 A bound) passes; 0.06 A trips; a phase that carries more than half of its
  // predicted current is never lost, whatever the shortfall; nor is one that carries more than
  // an open phase's noise can read (0.07 A on average), though it falls short by more than half.
  const auto judge = [](double predicted_A, double measured_A) {
    PhaseLossCheck<double> check(phase_loss_config());
    int lost = -1;
    for (int k = 0; k < 1 + 25; ++k) {  // the skipped first tick, then one window
      const double predicted[3] = {predicted_A, 3.0, -3.0}, measured[3] = {measured_A, 3.0, -3.0};
      lost = check.lost_phase(predicted, measured, 311.0);
    }
    return lost;
  };
  EXPECT_EQ(judge(0.04, 0.0), -1);
  EXPECT_EQ(judge(0.06, 0.0), 0);
  EXPECT_EQ(judge(2.0, 1.1), -1);
  EXPECT_EQ(judge(2.0, 0.9), -1);
  EXPECT_EQ(judge(2.0, 0.069), 0);
  EXPECT_EQ(judge(2.0, 0.071), -1);
}

TEST(PhaseLossCheck, APhaseThatCarriesCurrentIsNotLostThoughTheModelMissesIt) {
  // The window that latched phase_loss on a healthy 7.5 kW motor whose rotor was at half the
  // record's resistance, accelerating to 80 rad/s (240 rad/s electrical): the flux estimate
  // was off, and the one-step prediction turned the current vector by a few degrees. Summed
  // over the window, phase a was predicted 400 A and carried 192 A (less than half), b and c
  // carried more than predicted. An open phase carries only its noise: this one is connected.
  PhaseLossCheck<double>::Config c = phase_loss_config();
  // That board's window allowed 42.65 A of shortfall (1.706 A a tick on its 540 V bus): the
  // split between the inverter's share and the noise's does not matter to the verdict.
  c.missing_A_per_bus_V = 1.6 / 540.0;
  c.noise_floor_A = 0.106;
  c.open_mean_A = 0.34;  // its 50 A ADC's four codes of noise, times 3, and two codes
  PhaseLossCheck<double> check(c);
  const double predicted[3] = {400.0 / 25, 481.6 / 25, -881.3 / 25};
  const double measured[3] = {191.7 / 25, 577.5 / 25, -768.1 / 25};
  int lost = -1;
  for (int k = 0; k < 1 + 25; ++k) lost = check.lost_phase(predicted, measured, 540.0);
  EXPECT_EQ(lost, -1);
  // The same shortfall with phase a open (its noise alone) is a lost phase.
  PhaseLossCheck<double> open(c);
  const double open_measured[3] = {0.04, measured[1], measured[2]};
  for (int k = 0; k < 1 + 25; ++k) lost = open.lost_phase(predicted, open_measured, 540.0);
  EXPECT_EQ(lost, 0);
}

}  // namespace
}  // namespace imd::firmware
