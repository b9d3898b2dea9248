// Observers of paper 000, Section IV, and the encoder-driven observer: their error matrices,
// and their convergence on the exact sampled model.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <vector>

#include "control/encoder_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "control/flux_observer.hpp"
#include "control/load_estimator.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kDelta_s = 1e-4;

double spectral_radius(const Eigen::MatrixXd& m) {
  return m.eigenvalues().cwiseAbs().maxCoeff();
}

TEST(LoadEstimator, PrintedPaperGainsAreNotSchurStable) {
  // Section V prints l1 = 50, l2 = -45.78. Against the error equation (13) for the paper motor
  // the matrix [[-50, -0.01], [45.78, 1]] has eigenvalues 0.99 and -49.99.
  const auto c = discretize_voltage_fed(test::test_motors()[0].parameters, kDelta_s);
  const Eigen::Matrix2d m = load_estimator_error_matrix(c, {50.0, -45.78});
  const Eigen::Vector2cd eigenvalues = m.eigenvalues();
  const double small = std::min(std::abs(eigenvalues(0)), std::abs(eigenvalues(1)));
  const double large = std::max(std::abs(eigenvalues(0)), std::abs(eigenvalues(1)));
  EXPECT_NEAR(large, 49.99, 0.01);
  EXPECT_NEAR(small, 0.99, 0.01);
}

TEST(LoadEstimator, PlacedGainsGiveTheRequestedPoles) {
  for (const auto& motor : test::test_motors()) {
    const auto c = discretize_voltage_fed(motor.parameters, kDelta_s);
    const auto gains = place_load_estimator(c, 0.99, 0.985);
    Eigen::Vector2cd poles = load_estimator_error_matrix(c, gains).eigenvalues();
    if (poles(0).real() < poles(1).real()) std::swap(poles(0), poles(1));
    EXPECT_NEAR(poles(0).real(), 0.99, 1e-9) << motor.name;
    EXPECT_NEAR(poles(1).real(), 0.985, 1e-9) << motor.name;
  }
}

TEST(LoadEstimator, ConvergesToAStepOfLoadOnTheExactModel) {
  const auto c = discretize_voltage_fed(test::test_motors()[0].parameters, kDelta_s);
  const VoltageFedModel<double> model(c);
  LoadEstimator<double> estimator(c, place_load_estimator(c, 0.99, 0.99));
  RotorFrameState<double> x;
  x.flux_r_AB_Wb = {0.45, 0.0};
  x.i_s_AB_A = {1.2, 0.5};
  x.omega_mech_rad_s = 20.0;
  estimator.reset(x.omega_mech_rad_s);
  const Vec2<double> v(10.0, 20.0);
  const double load_Nm = 1.0;
  for (int k = 0; k < 1000; ++k) {  // 100 ms
    estimator.update(x.omega_mech_rad_s, x.i_s_AB_A, x.flux_r_AB_Wb, v);
    x = model.predict(x, v, load_Nm);
  }
  // Double pole at 0.99: the error after k steps is (1 + k (1 - z)/z) z^k ~ 11 e^-10 = 5e-4 of
  // the step (the drive's acceptance bound is 2 %); allow 1e-3.
  EXPECT_NEAR(estimator.load_Nm(), load_Nm, 1e-3 * load_Nm);
}

TEST(FluxObserver, ErrorDecaysAsA11ToTheK) {
  const auto c = discretize_voltage_fed(test::test_motors()[0].parameters, kDelta_s);
  const VoltageFedModel<double> model(c);
  FluxObserver<double> observer(c);
  RotorFrameState<double> x;
  x.flux_r_AB_Wb = {0.4, -0.1};
  x.i_s_AB_A = {1.0, 2.0};
  x.omega_mech_rad_s = 30.0;
  const Vec2<double> error0 = x.flux_r_AB_Wb - observer.flux_r_AB_Wb();
  const Vec2<double> v(50.0, -20.0);
  for (int k = 1; k <= 500; ++k) {
    observer.update(x.i_s_AB_A, v);
    x = model.predict(x, v, 0.0);
    const Vec2<double> error = x.flux_r_AB_Wb - observer.flux_r_AB_Wb();
    ASSERT_NEAR((error - std::pow(c.a11, k) * error0).norm(), 0.0, 1e-13) << "step " << k;
  }
}

TEST(EncoderObserver, PolesArePlaced) {
  for (const auto& motor : test::test_motors()) {
    const auto c = discretize_voltage_fed(motor.parameters, kDelta_s);
    const Eigen::Vector3d gain = place_encoder_observer(c, 400.0);
    const Eigen::Matrix3d error = encoder_observer_error_matrix(c, gain);
    // A triple pole: the characteristic polynomial is (z - z0)^3; compare its coefficients
    // (eigenvalues of a triple root are ill-conditioned, the coefficients are not).
    const double z0 = std::exp(-400.0 * kDelta_s);
    EXPECT_NEAR(error.trace(), 3 * z0, 1e-9) << motor.name;
    EXPECT_NEAR(error.determinant(), z0 * z0 * z0, 1e-9) << motor.name;
    EXPECT_LT(spectral_radius(error), 1.0);
  }
}

TEST(EncoderObserver, TracksSpeedAndLoadFromAQuantizedAngle) {
  // Exact model, a 8192-count encoder, constant input: speed and load must be recovered from
  // the quantized angle alone.
  const auto c = discretize_voltage_fed(test::test_motors()[0].parameters, kDelta_s);
  const VoltageFedModel<double> model(c);
  EncoderObserver<double> observer(c, {});
  RotorFrameState<double> x;
  x.flux_r_AB_Wb = {0.45, 0.0};
  x.i_s_AB_A = {1.2, 1.0};
  x.omega_mech_rad_s = 60.0;
  const Vec2<double> v(12.0, 40.0);
  const double load_Nm = 0.5, counts_per_rad = 8192 / (2 * std::numbers::pi);
  for (int k = 0; k < 2000; ++k) {
    const Vec2<double> i = x.i_s_AB_A, flux = x.flux_r_AB_Wb;
    x = model.predict(x, v, load_Nm);
    const double measured =
        std::floor(std::fmod(x.theta_mech_rad, 2 * std::numbers::pi) * counts_per_rad) /
        counts_per_rad;
    observer.update(i, flux, v, measured);
  }
  // Quantization of 7.7e-4 rad is the only error source; a 400 rad/s observer turns a
  // +-0.5 LSB angle error into a speed error of order 400 * 7.7e-4 = 0.3 rad/s at worst.
  EXPECT_NEAR(observer.omega_mech_rad_s(), x.omega_mech_rad_s, 0.3);
  EXPECT_NEAR(wrap_pi(observer.theta_mech_rad() - x.theta_mech_rad), 0.0, 2 * 7.7e-4);
  EXPECT_NEAR(observer.load_Nm(), load_Nm, 0.1);
}

}  // namespace
}  // namespace imd::control

namespace imd::control {
namespace {

// wrap_pi's fast path (one exact subtraction within two turns) must give fmod's result bit
// for bit, in both precisions, or the double runs would lose their reproducibility.
template <typename T>
T wrap_pi_by_fmod(T angle_rad) {
  const T two_pi = T(2 * std::numbers::pi);
  angle_rad = std::fmod(angle_rad + T(std::numbers::pi), two_pi);
  return (angle_rad < T(0) ? angle_rad + two_pi : angle_rad) - T(std::numbers::pi);
}

template <typename T>
void expect_wrap_pi_is_fmods() {
  for (int i = -200'000; i <= 200'000; ++i) {
    const T angle = T(i) * T(3.1e-4);  // -62 .. 62 rad: both paths
    ASSERT_EQ(wrap_pi(angle), wrap_pi_by_fmod(angle)) << angle;
  }
}

TEST(WrapPi, EqualsTheFmodFormulaBitForBit) {
  expect_wrap_pi_is_fmods<float>();
  expect_wrap_pi_is_fmods<double>();
}

}  // namespace
}  // namespace imd::control

namespace imd::control {
namespace {

TEST(EncoderObserver, QuantizationBoundsAreReachedAndNotExceeded) {
  constexpr double kCount = 2 * std::numbers::pi / 8192;
  for (const test::TestMotor& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const auto c = discretize_voltage_fed(motor.parameters, 1e-4);
    const QuantizationErrorBounds b = encoder_quantization_bounds(c, 400.0, kCount);
    // A rotor at rest: every error is the measurement's. The sequence that takes each step's
    // error to the sign of the speed error's impulse response at the end reaches the bound
    // there; a rotor dithering across a count edge, at any period, stays within it.
    const Eigen::Vector3d gain = place_encoder_observer(c, 400.0);
    const Eigen::Matrix3d error = encoder_observer_error_matrix(c, gain);
    const int n = 3000;
    std::vector<double> sign(n);
    Eigen::Vector3d response = gain;
    for (int j = 0; j < n; ++j, response = error * response) sign[j] = response(1) >= 0 ? 1 : -1;
    EncoderObserver<double> worst(c, {400.0});
    for (int k = 0; k < n; ++k) {
      worst.predict(Vec2<double>::Zero(), Vec2<double>::Zero(), Vec2<double>::Zero());
      worst.correct(kCount * sign[n - 1 - k]);
    }
    EXPECT_NEAR(worst.omega_mech_rad_s(), b.omega_rad_s, 1e-6 * b.omega_rad_s);
    for (int period : {1, 2, 3, 7, 20, 63, 200}) {
      EncoderObserver<double> dither(c, {400.0});
      for (int k = 0; k < 20000; ++k) {
        dither.predict(Vec2<double>::Zero(), Vec2<double>::Zero(), Vec2<double>::Zero());
        dither.correct((k / period) % 2 == 0 ? 0.0 : kCount);
        ASSERT_LE(std::abs(dither.omega_mech_rad_s()), b.omega_rad_s);
        ASSERT_LE(std::abs(dither.load_Nm()), b.load_Nm);
      }
    }
  }
}

}  // namespace
}  // namespace imd::control
