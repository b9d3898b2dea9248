// The stuck-ADC check on its own (firmware/protection/adc_stuck_check.hpp); with the other
// checks and the phase-loss wait in test_protection.cpp, on the simulated board in
// tests/hal_sim/test_adc_stuck_sweep.cpp and test_quiet_adc_sweep.cpp.
#include "firmware/protection/adc_stuck_check.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>

namespace imd::firmware {
namespace {

// A 12-bit converter over +-10 A: 4.9 mA per code, so four codes are 19.5 mA of evidence. The
// paper motor's sigma_H = 0.0259 H at 1e-4 s on a 300 V bus: phase currents within
// 300 x 1e-4 / (12 x 0.0259) = 96.5 mA of zero are in the zero-crossing band.
constexpr double kAPerCode = 10.0 / 2048, kSigmaH = 0.0259, kPeriodS = 1e-4, kBusV = 300.0;
constexpr double kFarFromZeroA[3] = {2.0, -1.0, -1.0};
using Vec2 = control::Vec2<double>;

AdcStuckCheck<double> stuck_check() { return {20, kAPerCode, kSigmaH, kPeriodS}; }

bool feed(AdcStuckCheck<double>& check, const std::array<uint16_t, 3>& codes, const Vec2& i_A,
           bool predicted = true, const double (&i_abc_A)[3] = kFarFromZeroA) {
  return check.stuck(codes, i_abc_A, kBusV, i_A, predicted);
}

TEST(AdcStuckCheck, RepeatedCodesWhileTheModelMovesTheCurrentAreStuck) {
  // The model predicts a 3 A vector turning by 0.05 rad per tick (a stuck reading under a
  // running law). The first call has nothing to repeat; the window is the next 20 calls, and
  // its second half's predictions depart from its first half's by
  // |sum_{k=11..20} 3 e^{0.05ik} - sum_{k=1..10} 3 e^{0.05ik}| = 14.7 A: stuck at its end, on
  // the 21st call.
  AdcStuckCheck<double> check = stuck_check();
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  int k = 0;
  bool stuck = false;
  for (double angle = 0.0; k < 200 && !stuck; ++k, angle += 0.05) {
    stuck = feed(check, codes, {3.0 * std::cos(angle), 3.0 * std::sin(angle)});
  }
  EXPECT_TRUE(stuck);
  EXPECT_EQ(k, 21);
}

TEST(AdcStuckCheck, TheSmallestEvidenceThatTrips) {
  // A prediction that steps by d at the window's second half (its 11th tick, the 12th call)
  // and stays: the second half departs from the first by 10 d. Four codes need d > 19.5 mA /
  // 10 = 1.95 mA: 1.9 mA is not stuck, 2.0 mA is.
  for (const double step_A : {1.9e-3, 2.0e-3}) {
    AdcStuckCheck<double> check = stuck_check();
    const std::array<uint16_t, 3> codes{2048, 2000, 2100};
    bool stuck = false;
    for (int k = 0; k <= 20; ++k) {
      stuck = feed(check, codes, {1.0 + (k >= 11 ? step_A : 0.0), 0.5});
      if (k < 20) {
        ASSERT_FALSE(stuck) << k;
      }
    }
    EXPECT_EQ(stuck, step_A > 4 * kAPerCode / 10) << step_A;
  }
}

TEST(AdcStuckCheck, AQuietConverterOnASteadyModelIsNot) {
  // The codes repeat and the model predicts the current they read, or any constant offset
  // from it (a constant model error cancels in the departures): at rest under a held voltage,
  // or at a standstill of the stator frequency while the voltage follows the back EMF.
  AdcStuckCheck<double> check = stuck_check();
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  for (int k = 0; k < 10000; ++k) ASSERT_FALSE(feed(check, codes, {1.7, -0.98}));
}

TEST(AdcStuckCheck, PredictionScatterIsNotEvidence) {
  // +-0.6 mA of scatter on both axes around a steady prediction, each tick 0.85 mA long at
  // most: a window's second half departs from its first by at most 20 x 0.85 mA = 17.0 mA,
  // under the 19.5 mA of four codes, whatever the pattern.
  AdcStuckCheck<double> check = stuck_check();
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  uint32_t lcg = 12345;
  for (int k = 0; k < 100000; ++k) {
    lcg = lcg * 1664525u + 1013904223u;
    const double scatter_A = (lcg >> 31) != 0 ? 0.6e-3 : -0.6e-3;
    ASSERT_FALSE(feed(check, codes, {1.7 + scatter_A, scatter_A})) << k;
  }
}

TEST(AdcStuckCheck, ChangingCodesAreNotStuck) {
  AdcStuckCheck<double> check = stuck_check();
  for (int k = 0; k < 10000; ++k) {
    const std::array<uint16_t, 3> codes{uint16_t(2048 + k % 2), 2000, 2100};
    ASSERT_FALSE(feed(check, codes, {3.0 * std::cos(k), 3.0 * std::sin(k)}));
  }
}

TEST(AdcStuckCheck, APhaseInTheZeroCrossingBandGivesNoEvidenceAlongItsAxis) {
  // Phase b reads 50 mA, within the 96.5 mA band: its current may clamp at zero while its pole
  // voltage error is unknown, so a prediction that departs along b's axis is no evidence. The
  // same departure across that axis is: 10 ticks of 2.5 mA (25 mA) are over four codes.
  const double clamped_b_A[3] = {1.0, 0.05, -1.05};
  const std::array<uint16_t, 3> codes{2248, 2058, 1833};
  const Vec2 along_b(-0.5, 0.8660254037844386), across_b(0.8660254037844386, 0.5);
  for (const bool across : {false, true}) {
    AdcStuckCheck<double> check = stuck_check();
    bool stuck = false;
    for (int k = 0; k <= 20; ++k) {
      const Vec2 departure = (k >= 11 ? 2.5e-3 : 0.0) * (across ? across_b : along_b);
      stuck = feed(check, codes, Vec2(0.9, 0.6) + departure, true, clamped_b_A);
    }
    EXPECT_EQ(stuck, across) << (across ? "across" : "along") << " phase b's axis";
  }
}

TEST(AdcStuckCheck, TwoPhasesInTheBandGiveNoEvidence) {
  // A current within the band on two phases is near zero: every direction is uncertain.
  const double near_zero_A[3] = {0.09, -0.05, -0.04};
  const std::array<uint16_t, 3> codes{2066, 2038, 2040};
  AdcStuckCheck<double> check = stuck_check();
  for (int k = 0; k < 2000; ++k) {
    ASSERT_FALSE(feed(check, codes, {3.0 * std::cos(0.05 * k), 3.0 * std::sin(0.05 * k)}, true,
                      near_zero_A));
  }
}

TEST(AdcStuckCheck, WithoutAPredictionNoWindowRuns) {
  // No prediction (the first tick after the PWM was off, DC braking): no evidence is taken,
  // and a window starts at the next predicted tick: stuck on its 20th, the 20th call.
  AdcStuckCheck<double> check = stuck_check();
  const std::array<uint16_t, 3> codes{2048, 2000, 2100};
  for (int k = 0; k < 1000; ++k) {
    ASSERT_FALSE(feed(check, codes, {3.0 * std::cos(0.05 * k), 3.0 * std::sin(0.05 * k)}, false));
  }
  int k = 0;
  bool stuck = false;
  for (; k < 200 && !stuck; ++k) {
    stuck = feed(check, codes, {3.0 * std::cos(0.05 * k), 3.0 * std::sin(0.05 * k)});
  }
  EXPECT_TRUE(stuck);
  EXPECT_EQ(k, 20);
}

}  // namespace
}  // namespace imd::firmware
