// Exact sampled model of paper 000 against the continuous plant with the ideal analog feedback
// (2), and the derived quantities of Sections II and IV.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "control/voltage_fed_model.hpp"
#include "control/current_fed_model.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kDelta_s = 1e-4;  // the paper's sample period

// A matrix exponential by scaling and squaring with a degree-13 Pade approximant has a
// relative error of a few ulp times the number of squarings; here |A delta| < 1, so a handful
// of squarings at most. 1e-12 leaves two orders of magnitude of margin.
constexpr double kExpmTolerance = 1e-12;

// The exact model must match a very fine integration of the continuous model to 1e-9. With
// 1000 RK4 substeps per period (h = 1e-7 s) the truncation error per step is of order
// (|lambda| h)^5 / 120 with |lambda| < 1e4 (stator dynamics plus p w), i.e. < 1e-17, and the
// rounding error accumulated over 1000 steps is of order 1e-13: the check measures the model.
constexpr int kFineSubsteps = 1000;
constexpr double kExactnessTolerance = 1e-9;
constexpr double kIncrementTolerance = 1e-10;

double relative_error(const Vec2<double>& value, const Vec2<double>& reference) {
  return (value - reference).norm() / reference.norm();
}
double relative_error(double value, double reference) {
  return std::abs(value - reference) / std::abs(reference);
}

struct Draw {
  RotorFrameState<double> x;
  Vec2<double> v_AB_V;
  double load_Nm;
};

/// A random state and input at the motor's typical magnitudes. Magnitudes are kept away from
/// zero (at least 20 % of typical) so that relative errors are meaningful.
Draw random_draw(std::mt19937_64& rng, const test::TestMotor& m) {
  std::uniform_real_distribution<double> unit(0.2, 1.0);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::bernoulli_distribution negative(0.5);
  const auto vector = [&](double magnitude) {
    const double a = angle(rng);
    const double r = magnitude * unit(rng);
    return Vec2<double>(r * std::cos(a), r * std::sin(a));
  };
  Draw d;
  d.x.flux_r_AB_Wb = vector(m.flux_Wb);
  d.x.i_s_AB_A = vector(m.current_A);
  d.x.omega_mech_rad_s = (negative(rng) ? -1.0 : 1.0) * m.speed_rad_s * unit(rng);
  d.x.theta_mech_rad = std::uniform_real_distribution<double>(0.5, 6.0)(rng);
  d.v_AB_V = vector(m.voltage_V);
  d.load_Nm = (negative(rng) ? -1.0 : 1.0) * m.load_Nm * unit(rng);
  return d;
}

/// Size of the terms that make up the speed and position increments: the natural scale to
/// judge an increment's error against (the increment itself can nearly cancel).
MechanicalIncrement<double> increment_scale(const VoltageFedCoefficients& c, const Draw& d) {
  const double flux = d.x.flux_r_AB_Wb.norm(), current = d.x.i_s_AB_A.norm(), v = d.v_AB_V.norm();
  const double omega = std::abs(d.x.omega_mech_rad_s), load = std::abs(d.load_Nm);
  return {std::abs(c.omega_decay_minus_one) * omega + std::abs(c.eta1) * current * flux +
              std::abs(c.eta2) * flux * v + std::abs(c.eta3) * current * v +
              std::abs(c.load_to_omega) * load,
          std::abs(c.omega_to_theta_s) * omega + std::abs(c.kappa1) * current * flux +
              std::abs(c.kappa2) * flux * v + std::abs(c.kappa3) * current * v +
              std::abs(c.load_to_theta) * load};
}

TEST(VoltageFedModel, OneStepMatchesFineIntegrationOfThePlant) {
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const int p = motor.parameters.pole_pairs;
    const auto coefficients = discretize_voltage_fed(motor.parameters, kDelta_s);
    const VoltageFedModel<double> model(coefficients);
    sim::InductionMotorPlant plant(motor.parameters, {kDelta_s, kFineSubsteps});
    std::mt19937_64 rng(2024);
    double worst_flux = 0, worst_current = 0, worst_speed = 0, worst_position = 0;
    double worst_speed_step = 0, worst_position_step = 0;
    for (int trial = 0; trial < 200; ++trial) {
      const Draw d = random_draw(rng, motor);
      const auto to_stator = Rotation<double>::from_angle(p * d.x.theta_mech_rad);
      plant.set_state({to_stator.apply(d.x.flux_r_AB_Wb), to_stator.apply(d.x.i_s_AB_A),
                       d.x.omega_mech_rad_s, d.x.theta_mech_rad});
      plant.step_analog_feedback(d.v_AB_V, d.load_Nm);
      const sim::PlantState& s = plant.state();
      const auto to_rotor = Rotation<double>::from_angle(p * s.theta_mech_rad);

      const RotorFrameState<double> predicted = model.predict(d.x, d.v_AB_V, d.load_Nm);
      worst_flux = std::max(
          worst_flux,
          relative_error(predicted.flux_r_AB_Wb, to_rotor.apply_inverse(s.flux_r_alphabeta_Wb)));
      worst_current =
          std::max(worst_current,
                   relative_error(predicted.i_s_AB_A, to_rotor.apply_inverse(s.i_s_alphabeta_A)));
      worst_speed =
          std::max(worst_speed, relative_error(predicted.omega_mech_rad_s, s.omega_mech_rad_s));
      worst_position =
          std::max(worst_position, relative_error(predicted.theta_mech_rad, s.theta_mech_rad));
      // The increments, against the size of their terms: sensitive to every coefficient.
      const auto step = model.increment(d.x, d.v_AB_V, d.load_Nm);
      const auto scale = increment_scale(coefficients, d);
      worst_speed_step =
          std::max(worst_speed_step,
                   std::abs(step.omega_mech_rad_s - (s.omega_mech_rad_s - d.x.omega_mech_rad_s)) /
                       scale.omega_mech_rad_s);
      worst_position_step =
          std::max(worst_position_step,
                   std::abs(step.theta_mech_rad - (s.theta_mech_rad - d.x.theta_mech_rad)) /
                       scale.theta_mech_rad);
    }
    std::printf(
        "%-18s worst relative error: flux %.2e current %.2e speed %.2e position %.2e"
        " | increments: speed %.2e position %.2e\n",
        motor.name.c_str(), worst_flux, worst_current, worst_speed, worst_position,
        worst_speed_step, worst_position_step);
    EXPECT_LE(worst_flux, kExactnessTolerance);
    EXPECT_LE(worst_current, kExactnessTolerance);
    EXPECT_LE(worst_speed, kExactnessTolerance);
    EXPECT_LE(worst_position, kExactnessTolerance);
    // The plant's speed and position carry rounding of about one ulp of their value
    // (compensated summation), 6e-14 at 250 rad/s; the increment terms are at least ~1e-3, so
    // the floor is ~1e-10 at worst. A coefficient wrong by its own size (kappa3 = 0 moves the
    // position step by ~1e-8 of its scale) stays far above that.
    EXPECT_LE(worst_speed_step, kIncrementTolerance);
    EXPECT_LE(worst_position_step, kIncrementTolerance);
  }
}

/// Composite Simpson rule on [0, delta] with n (even) intervals.
template <typename F>
double simpson(const F& f, double delta, int n) {
  const double h = delta / n;
  double sum = f(0.0) + f(delta);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(i * h);
  return sum * h / 3.0;
}

TEST(VoltageFedModel, CoefficientsMatchQuadratureOfTheMinors) {
  // An independent route to eta and kappa: integrate the 2x2 minors of exp(A3 u) (no compound
  // matrix, no block exponential) with Simpson's rule, whose error falls as n^-4. The hardest
  // integrand is kappa3's, which starts as u^2 (delta - u): with 400 intervals it is still off
  // by 2e-12 relative, with 1600 by 256 times less (measured). The minors are evaluated in long
  // double, so that the absolute rounding of the small input column of exp(A3 u) does not enter.
  // Left over is the rounding of the coefficients under test: 1e-12.
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const auto c = discretize_voltage_fed(motor.parameters, kDelta_s);
    const double mu = derive_voltage_fed(motor.parameters).mu_per_kgm2;
    const double f = motor.parameters.friction_Nms / motor.parameters.J_kgm2;
    using Matrix3l = Eigen::Matrix<long double, 3, 3>;
    const Matrix3l a = voltage_fed_axis_generator(motor.parameters).cast<long double>();
    const auto minor = [&](double u, int j, int l) {
      const Matrix3l e = (a * static_cast<long double>(u)).exp();
      return static_cast<double>(e(0, j) * e(1, l) - e(0, l) * e(1, j));
    };
    const auto speed_weight = [&](double u) { return std::exp(-f * (kDelta_s - u)); };
    const auto position_weight = [&](double u) {  // (1 - e^{-f (delta - u)}) / f
      return (kDelta_s - u) * phi1(-f * (kDelta_s - u));
    };
    const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    const double signs[3] = {1.0, -1.0, -1.0};
    const double eta[3] = {c.eta1, c.eta2, c.eta3}, kappa[3] = {c.kappa1, c.kappa2, c.kappa3};
    for (int i = 0; i < 3; ++i) {
      const int j = pairs[i][0], l = pairs[i][1];  // not a structured binding: clang 14 cannot
                                                    // capture one in a lambda
      const double eta_q =
          signs[i] * mu *
          simpson([&](double u) { return minor(u, j, l) * speed_weight(u); }, kDelta_s, 1600);
      const double kappa_q =
          signs[i] * mu *
          simpson([&](double u) { return minor(u, j, l) * position_weight(u); }, kDelta_s, 1600);
      EXPECT_NEAR(eta[i], eta_q, 1e-12 * std::abs(eta_q)) << "eta" << i + 1;
      EXPECT_NEAR(kappa[i], kappa_q, 1e-12 * std::abs(kappa_q)) << "kappa" << i + 1;
    }
  }
}

TEST(VoltageFedModel, FluxObserverPoleIsInsideTheUnitCircle) {
  // Section IV: the flux observer error obeys e_{k+1} = a11 e_k and needs |a11| < 1.
  for (const auto& motor : test::test_motors()) {
    for (const double delta_s : {1e-5, 1e-4, 1e-3, 1e-2}) {
      const auto c = discretize_voltage_fed(motor.parameters, delta_s);
      EXPECT_GT(c.a11, 0.0) << motor.name;
      EXPECT_LT(std::abs(c.a11), 1.0) << motor.name << " delta " << delta_s;
    }
  }
}

TEST(VoltageFedModel, Eta1MatchesItsClosedForm) {
  // q = I~^T J Phi~ is multiplied by det exp(A2 t) = exp(t tr A2), so with c = 0
  // eta1 = mu (e^{delta tr A2} - 1) / tr A2, tr A2 = -alpha - gamma (paper motor, c = 0).
  // With friction f = c/J the integral carries the weight e^{-f (delta - t)}:
  // eta1 = mu e^{-f delta} delta phi1((tr A2 + f) delta).
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const auto k = derive_voltage_fed(motor.parameters);
    const double trace = -k.alpha_per_s - k.gamma_per_s;
    const double f = motor.parameters.friction_Nms / motor.parameters.J_kgm2;
    const auto c = discretize_voltage_fed(motor.parameters, kDelta_s);
    const double closed =
        k.mu_per_kgm2 * std::exp(-f * kDelta_s) * kDelta_s * phi1((trace + f) * kDelta_s);
    EXPECT_NEAR(c.eta1, closed, kExpmTolerance * std::abs(closed));
    if (f == 0.0) {
      const double paper = k.mu_per_kgm2 * (std::exp(kDelta_s * trace) - 1.0) / trace;
      // The paper's form cancels in e^x - 1 for small x: about 1e-16 / |x| relative.
      EXPECT_NEAR(
          c.eta1, paper,
          1e-16 / std::abs(kDelta_s * trace) * std::abs(paper) + kExpmTolerance * std::abs(paper));
    }
  }
}

TEST(VoltageFedModel, CompoundMatrixGivesTheMinorsOfTheExponential) {
  // The derivation rests on C2(exp(A t)) = exp(A^[2] t): check it against the 2x2 minors.
  for (const auto& motor : test::test_motors()) {
    const Eigen::Matrix3d a = voltage_fed_axis_generator(motor.parameters);
    for (const double t : {1e-4, 1e-3, 2e-2}) {
      const Eigen::Matrix3d e = (a * t).exp();
      const Eigen::Matrix3d c = (additive_compound(a) * t).exp();
      const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
      for (int r = 0; r < 3; ++r) {
        for (int s = 0; s < 3; ++s) {
          const auto [i, j] = pairs[r];
          const auto [k, l] = pairs[s];
          const double minor = e(i, k) * e(j, l) - e(i, l) * e(j, k);
          EXPECT_NEAR(c(r, s), minor, kExpmTolerance * std::max(1.0, c.norm()))
              << motor.name << " t " << t << " entry " << r << s;
        }
      }
    }
  }
}

TEST(VoltageFedModel, FrictionlessMechanicsReduceToThePaper) {
  const test::TestMotor motor = test::test_motors().front();  // seed000: c = 0
  const auto c = discretize_voltage_fed(motor.parameters, kDelta_s);
  const double J = motor.parameters.J_kgm2;
  EXPECT_EQ(c.omega_decay, 1.0);
  EXPECT_NEAR(c.omega_to_theta_s, kDelta_s, 1e-16 * kDelta_s);
  EXPECT_NEAR(c.load_to_omega, -kDelta_s / J, 1e-15 * kDelta_s / J);
  EXPECT_NEAR(c.load_to_theta, -kDelta_s * kDelta_s / (2 * J), 1e-15 * kDelta_s * kDelta_s / J);
}

TEST(VoltageFedModel, FloatPredictorStaysCloseToDouble) {
  // The MCU build runs the predictor in float. Each output is a short sum of products of
  // values of one magnitude, and the draws keep outputs away from zero, so the float result
  // is within a few float ulp (6e-8) of double: bound 1e-6, i.e. about 16 ulp. The increments
  // are checked the same way against the size of their terms: there the small eta3 and kappa3
  // terms must survive, which they would not if added to w_k or th_k in float.
  for (const auto& motor : test::test_motors()) {
    const auto coefficients = discretize_voltage_fed(motor.parameters, kDelta_s);
    const VoltageFedModel<double> model_d(coefficients);
    const VoltageFedModel<float> model_f(coefficients);
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
      const Draw d = random_draw(rng, motor);
      RotorFrameState<float> xf{d.x.flux_r_AB_Wb.cast<float>(), d.x.i_s_AB_A.cast<float>(),
                                float(d.x.omega_mech_rad_s), float(d.x.theta_mech_rad)};
      const auto nd = model_d.predict(d.x, d.v_AB_V, d.load_Nm);
      const auto nf = model_f.predict(xf, d.v_AB_V.cast<float>(), float(d.load_Nm));
      EXPECT_LE(relative_error(nf.flux_r_AB_Wb.cast<double>(), nd.flux_r_AB_Wb), 1e-6);
      EXPECT_LE(relative_error(nf.i_s_AB_A.cast<double>(), nd.i_s_AB_A), 1e-6);
      EXPECT_LE(relative_error(double(nf.omega_mech_rad_s), nd.omega_mech_rad_s), 1e-6);
      EXPECT_LE(relative_error(double(nf.theta_mech_rad), nd.theta_mech_rad), 1e-6);
      const auto step_d = model_d.increment(d.x, d.v_AB_V, d.load_Nm);
      const auto step_f = model_f.increment(xf, d.v_AB_V.cast<float>(), float(d.load_Nm));
      const auto scale = increment_scale(coefficients, d);
      EXPECT_LE(std::abs(step_f.omega_mech_rad_s - step_d.omega_mech_rad_s),
                1e-6 * scale.omega_mech_rad_s);
      EXPECT_LE(std::abs(step_f.theta_mech_rad - step_d.theta_mech_rad),
                1e-6 * scale.theta_mech_rad);
    }
  }
}

}  // namespace
}  // namespace imd::control
