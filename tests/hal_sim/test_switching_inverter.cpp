// The switching inverter (hal_sim/switching_inverter.hpp): its period's segments average to
// what the average model applies, dead time and drop included, and on the board its current
// ripple is that of the transient inductance.
#include <gtest/gtest.h>

#include <cmath>

#include "control/svpwm.hpp"
#include "firmware/paper_motor.hpp"
#include "hal_sim/inverter_model.hpp"
#include "hal_sim/sensor_models.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/switching_inverter.hpp"

namespace imd::sim {
namespace {

constexpr double kPeriod_s = 1e-4;
constexpr double kBus_V = 311.0;

double total_s(const PwmPeriod& p) {
  double t = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) t += p.segments[i].duration_s;
  return t;
}

TEST(SwitchingInverter, AnIdealInvertersPeriodAveragesToTheDutiesVoltage) {
  const hal::PhaseDuties duty{0.8f, 0.35f, 0.1f};
  const PwmPeriod p = switching_period({}, duty, kBus_V, kPeriod_s, Vec2(2.0, -1.0));
  EXPECT_NEAR(total_s(p), kPeriod_s, 1e-18);
  EXPECT_EQ(p.count, 7u);  // three legs, six distinct edges
  EXPECT_NEAR((p.average_V() - inverter_output_V(duty, kBus_V)).norm(), 0.0, 1e-9);
  // Centre-aligned: the first and last segments are the zero vector (all legs low).
  EXPECT_NEAR(p.segments[0].u_alphabeta_V.norm(), 0.0, 1e-12);
  EXPECT_NEAR(p.segments[p.count - 1].u_alphabeta_V.norm(), 0.0, 1e-12);
}

TEST(SwitchingInverter, DeadTimeAndDropAverageToTheAverageModelsError) {
  // Every leg switching, each phase current away from zero: the mean over the period must be the
  // average model's voltage plus its error (inverter_model.hpp), to rounding.
  const InverterNonideality inverter{2e-6, 1.2};
  for (const Vec2& current : {Vec2(3.0, 0.5), Vec2(-2.0, 1.5), Vec2(0.4, -2.5)}) {
    const hal::PhaseDuties duty{0.7f, 0.45f, 0.2f};
    const PwmPeriod p = switching_period(inverter, duty, kBus_V, kPeriod_s, current);
    const Vec2 expected = inverter_output_V(duty, kBus_V) +
                          inverter_error_V(inverter, duty, kBus_V, kPeriod_s, current);
    EXPECT_NEAR(total_s(p), kPeriod_s, 1e-18);
    EXPECT_NEAR((p.average_V() - expected).norm(), 0.0, 1e-9) << current.transpose();
  }
}

TEST(SwitchingInverter, TheRippleIsTheTransientInductancesOnTheBoard) {
  // Rotor locked (huge J), one held duty pattern: the current ripple within a period follows
  // from sigma L dI/dt = u - (the back-EMF and the resistive drop, nearly constant over 100 us).
  // In the active segments u departs from the period's mean by the switched vector; the
  // triangle-like ripple's RMS is then about |u - u_mean| t / (2 sqrt 3 sigma) per segment.
  // Rather than the closed form, compare with the integral of the segments' voltages: the
  // current's deviation from its mean is the integral of (u - u_mean) / sigma.
  control::MotorParameters motor = test::paper_motor();
  motor.J_kgm2 = 1e9;
  SimBoardConfig config;
  config.switching_inverter = true;
  SimBoard board(motor, config);
  const hal::PhaseDuties duty{0.62f, 0.45f, 0.43f};
  board.pwm().set_duties(duty);
  board.pwm().enable();
  for (int k = 0; k < 2000; ++k) board.run_tick();  // to its steady state (tau_s ~ 3 ms)
  const double sigma_H = control::derive_voltage_fed(motor).sigma_H;
  const PwmPeriod p =
      switching_period({}, duty, kBus_V, kPeriod_s, board.plant().state().i_s_alphabeta_A);
  // The current's path relative to its start: integral of (u - u_mean) / sigma, sampled finely.
  const Vec2 mean_V = p.average_V();
  Vec2 delta = Vec2::Zero(), sum = Vec2::Zero();
  double sum_sq = 0.0;
  const int n = 20000;
  std::size_t segment = 0;
  double segment_end = p.segments[0].duration_s;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * kPeriod_s / n;
    while (t > segment_end && segment + 1 < p.count)
      segment_end += p.segments[++segment].duration_s;
    delta += (p.segments[segment].u_alphabeta_V - mean_V) / sigma_H * (kPeriod_s / n);
    sum += delta;
    sum_sq += delta.squaredNorm();
  }
  const double expected_sq = sum_sq / n - (sum / n).squaredNorm();
  // The plant's figure includes the exponential decay over the period (tau_s 3 ms against
  // 100 us: 3 %) and the current taken linear between its steps: 10 % covers both.
  EXPECT_NEAR(board.plant().period_ripple_sq_A2(), expected_sq, 0.1 * expected_sq);
  EXPECT_GT(expected_sq, 1e-6);  // a ripple of some milliamperes, not nothing
}

}  // namespace
}  // namespace imd::sim
