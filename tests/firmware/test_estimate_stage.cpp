// The estimate stage with PWM latency: the observers advance to the latency predictor's state
// (ObserverEstimator::advance_to) instead of computing the same rows again (advance). Both
// must leave the observers where the other does, on every test motor and random states.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "control/voltage_fed_model.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/latency_predictor.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

template <typename T>
class EstimateStage : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(EstimateStage, Precisions);

TYPED_TEST(EstimateStage, AdvancingToThePredictionEqualsAdvancingByTheModel) {
  using T = TypeParam;
  using Vec2 = control::Vec2<T>;
  const double pi = 3.14159265358979323846;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const test::TestMotor& motor : test::test_motors()) {
    const auto c = control::discretize_voltage_fed(motor.parameters, 1e-4);
    for (int trial = 0; trial < 100; ++trial) {
      ObserverEstimator<T> by_model(c, Real(motor.parameters.pole_pairs), Real(400.0));
      ObserverEstimator<T> to_prediction = by_model;
      LatencyPredictor<T> predictor(c, 1, true);
      const auto random_current = [&] {
        return Vec2(T(motor.current_A * unit(rng)), T(motor.current_A * unit(rng)));
      };
      const auto random_voltage = [&] {
        return Vec2(T(motor.voltage_V * unit(rng)), T(motor.voltage_V * unit(rng)));
      };
      // A first tick sets the angle and gives the observers a state of their own.
      Measurement<T> m;
      m.valid = true;
      m.encoder_first = true;
      m.theta_encoder_rad = T(pi * (1.0 + unit(rng)));
      m.i_alphabeta_A = random_current();
      const Vec2 v_first = random_voltage();
      by_model.estimate(m);
      by_model.advance(v_first);
      to_prediction.estimate(m);
      to_prediction.advance(v_first);
      // The tick under test: the voltage in flight acts over [k, k+1].
      const Vec2 v_in_flight = random_voltage();
      predictor.written(v_in_flight);
      m.encoder_first = false;
      m.theta_encoder_rad = T(pi * (1.0 + unit(rng)));
      m.i_alphabeta_A = random_current();
      by_model.estimate(m);
      by_model.advance(v_in_flight);
      Estimate<T> e = to_prediction.estimate(m);
      predictor.set_input_state(e);
      ASSERT_NE(predictor.next_state(), nullptr);
      to_prediction.advance_to(*predictor.next_state());
      // Both estimate the next tick alike.
      m.theta_encoder_rad = T(pi * (1.0 + unit(rng)));
      m.i_alphabeta_A = random_current();
      const Estimate<T> a = by_model.estimate(m), b = to_prediction.estimate(m);
      // The same rows on the same operands in the same order: the same bits. (This test is
      // built with -ffp-contract=off: a compiler that fused a product and a sum in one place
      // and not in the other would round them apart by an ulp, as it may on the MCU.)
      EXPECT_EQ(a.x.theta_mech_rad, b.x.theta_mech_rad) << motor.name;
      EXPECT_EQ(a.x.omega_mech_rad_s, b.x.omega_mech_rad_s) << motor.name;
      EXPECT_EQ(a.load_Nm, b.load_Nm) << motor.name;
      EXPECT_EQ(a.x.flux_r_AB_Wb, b.x.flux_r_AB_Wb) << motor.name;
      EXPECT_EQ(a.i_predicted_alphabeta_A, b.i_predicted_alphabeta_A) << motor.name;
      EXPECT_EQ(a.current_predicted, b.current_predicted);
    }
  }
}

TYPED_TEST(EstimateStage, WithoutLatencyThereIsNoPredictionToAdvanceTo) {
  using T = TypeParam;
  const auto c = control::discretize_voltage_fed(test::test_motors()[0].parameters, 1e-4);
  LatencyPredictor<T> no_latency(c, 0, true), not_compensated(c, 1, false);
  EXPECT_EQ(no_latency.next_state(), nullptr);
  EXPECT_EQ(not_compensated.next_state(), nullptr);
}

}  // namespace
}  // namespace imd::firmware
