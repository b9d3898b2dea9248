// Exact discrete model of paper 001, (14), (15), (17), (18), against the current-fed plant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "control/current_fed_model.hpp"
#include "hal_sim/induction_motor_plant.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kT0_s = 1e-3;  // the paper's control period
// The plant runs the period as 10 slices of 100 RK4 steps (h = 1e-6 s), so that the torque can
// be read inside the period. The current-fed dynamics are slow (|lambda| < alpha + p w < 1e3),
// so RK4 truncation is (1e-3)^5 / 120 per step, far below rounding; the accumulated rounding
// over 1000 steps is of order 1e-13. Against 1e-9 the check measures the model.
constexpr int kSlices = 10;
constexpr int kSubstepsPerSlice = 100;
constexpr double kExactnessTolerance = 1e-9;

struct Draw {
  Vec2<double> flux_r_alphabeta_Wb, i_now_AB_A, i_next_AB_A;
  double omega_mech_rad_s, theta_mech_rad, load_Nm;
};

Draw random_draw(std::mt19937_64& rng, const test::TestMotor& m) {
  std::uniform_real_distribution<double> unit(0.2, 1.0);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  const auto vector = [&](double magnitude) {
    const double a = angle(rng);
    const double r = magnitude * unit(rng);
    return Vec2<double>(r * std::cos(a), r * std::sin(a));
  };
  const auto sign = [&] { return std::bernoulli_distribution(0.5)(rng) ? -1.0 : 1.0; };
  return {vector(m.flux_Wb),
          vector(m.current_A),
          vector(m.current_A),
          sign() * m.speed_rad_s * unit(rng),
          std::uniform_real_distribution<double>(0.5, 6.0)(rng),
          sign() * m.load_Nm * unit(rng)};
}

/// Stator flux sigma I + (Lm/Lr) Phi in the rotor frame, for a given stator current there.
Vec2<double> stator_flux_AB(const MotorParameters& m, const sim::PlantState& s,
                            const Vec2<double>& i_AB_A) {
  const auto rotor = Rotation<double>::from_angle(m.pole_pairs * s.theta_mech_rad);
  const double sigma_H = derive_voltage_fed(m).sigma_H;
  return sigma_H * i_AB_A + m.Lm_H / m.Lr_H * rotor.apply_inverse(s.flux_r_alphabeta_Wb);
}

TEST(CurrentFedModel, OneStepMatchesTheCurrentFedPlant) {
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const MotorParameters& m = motor.parameters;
    const auto coefficients = discretize_current_fed(m, kT0_s);
    const CurrentFedModel<double> model(coefficients);
    sim::InductionMotorPlant plant(m, {kT0_s / kSlices, kSubstepsPerSlice});
    std::mt19937_64 rng(1001);
    double worst_flux = 0, worst_speed = 0, worst_torque = 0;
    for (int trial = 0; trial < 200; ++trial) {
      const Draw d = random_draw(rng, motor);
      const auto rotor = Rotation<double>::from_angle(m.pole_pairs * d.theta_mech_rad);
      plant.set_state(
          {d.flux_r_alphabeta_Wb, rotor.apply(d.i_now_AB_A), d.omega_mech_rad_s, d.theta_mech_rad});
      const Vec2<double> flux_now = stator_flux_AB(m, plant.state(), d.i_now_AB_A);
      const double torque_now = model.torque_Nm(flux_now, d.i_now_AB_A);  // (14)
      // Torque errors are relative to the torque scale k_T |i| |psi| (the value for orthogonal
      // vectors): a random draw can make the torque itself almost zero.
      const double torque_scale =
          coefficients.torque_per_flux_A * d.i_now_AB_A.norm() * flux_now.norm();
      worst_torque =
          std::max(worst_torque, std::abs(torque_now - plant.torque_Nm()) / torque_scale);
      for (int slice = 1; slice <= kSlices; ++slice) {
        plant.step_current_fed(d.i_now_AB_A, d.load_Nm);
        // Inside the period the torque decays as tau_k e^{-eta (t - t_k)}.
        const double expected =
            torque_now * std::exp(-coefficients.eta_per_s * kT0_s * slice / kSlices);
        worst_torque =
            std::max(worst_torque, std::abs(plant.torque_Nm() - expected) / torque_scale);
      }
      const Vec2<double> flux_next = stator_flux_AB(m, plant.state(), d.i_next_AB_A);
      const Vec2<double> predicted = model.next_stator_flux(flux_now, d.i_now_AB_A, d.i_next_AB_A);
      worst_flux = std::max(worst_flux, (predicted - flux_next).norm() / flux_next.norm());
      const double speed = model.next_speed(d.omega_mech_rad_s, torque_now, d.load_Nm);
      worst_speed = std::max(worst_speed, std::abs(speed - plant.state().omega_mech_rad_s) /
                                              std::abs(plant.state().omega_mech_rad_s));
    }
    std::printf("%-18s worst relative error: stator flux %.2e speed %.2e torque %.2e\n",
                motor.name.c_str(), worst_flux, worst_speed, worst_torque);
    EXPECT_LE(worst_flux, kExactnessTolerance);
    EXPECT_LE(worst_speed, kExactnessTolerance);
    EXPECT_LE(worst_torque, kExactnessTolerance);
  }
}

TEST(CurrentFedModel, ZeroFrictionGivesThePapersLoadTerm) {
  // (18) with c = 0: the load enters as T0 / J, and the speed does not decay.
  MotorParameters m = test::test_motors()[1].parameters;
  m.friction_Nms = 0.0;
  const auto c = discretize_current_fed(m, kT0_s);
  EXPECT_EQ(c.speed_decay, 1.0);
  EXPECT_DOUBLE_EQ(c.load_to_speed, -kT0_s / m.J_kgm2);
  const double eta = derive_current_fed(m).eta_per_s;
  // The paper's form 1 - e^{-x} cancels for small x = eta T0 (2e-3 here): the reference itself
  // carries a relative error of about eps / x, so allow 4 eps / x.
  const double x = eta * kT0_s;
  EXPECT_NEAR(c.torque_to_speed, (1.0 - std::exp(-x)) / (m.J_kgm2 * eta),
              4.0 * std::numeric_limits<double>::epsilon() / x * c.torque_to_speed);
}

TEST(CurrentFedModel, CoefficientsAreContinuousWhereTheFormulasDivideByZero) {
  // (17) divides by J eta - c and (18) by c. Both limits must be finite and continuous.
  MotorParameters m = test::test_motors()[1].parameters;
  const double eta = derive_current_fed(m).eta_per_s;
  m.friction_Nms = eta * m.J_kgm2;  // J eta = c exactly
  const auto at = discretize_current_fed(m, kT0_s);
  // Limit: T0 e^{-eta T0} / J.
  const double limit = kT0_s * std::exp(-eta * kT0_s) / m.J_kgm2;
  EXPECT_NEAR(at.torque_to_speed, limit, 1e-14 * limit);
  m.friction_Nms *= 1.0 + 1e-9;
  const auto near = discretize_current_fed(m, kT0_s);
  EXPECT_NEAR(near.torque_to_speed, limit, 1e-9 * limit);
  m.friction_Nms = 1e-300;
  EXPECT_NEAR(discretize_current_fed(m, kT0_s).load_to_speed, -kT0_s / m.J_kgm2,
              1e-15 * kT0_s / m.J_kgm2);
}

}  // namespace
}  // namespace imd::control
