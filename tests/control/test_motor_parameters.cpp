// Derived constants of both papers, and the validation rules of the motor parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "control/motor_parameters.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

const MotorParameters kPaper000{14.0, 0.4, 0.377, 10.1, 0.4128, 0.01, 1, 0.0};

// The constants are sums and quotients of a few inputs, each rounded to the design arithmetic
// Real by half an epsilon; the leakage sigma amplifies that by its conditioning Ls / sigma (7
// for the paper motor, tens at most for the test motors' identities below) in itself and in
// every constant that divides by it. 64 epsilons of Real, relative: 1.4e-14 in double.
constexpr double kRoundoff = 64 * std::numeric_limits<Real>::epsilon();

TEST(MotorParameters, VoltageFedConstantsOfThePaperMotor) {
  // Reference values evaluated independently (Python, double) from the formulas under (1).
  const VoltageFedConstants k = derive_voltage_fed(kPaper000);
  EXPECT_NEAR(k.sigma_H, 0.055695251937984525, kRoundoff * 0.0557);
  EXPECT_NEAR(k.alpha_per_s, 24.467054263565892, kRoundoff * 24.5);
  EXPECT_NEAR(k.beta_per_H, 16.39772084728806, kRoundoff * 16.4);
  EXPECT_NEAR(k.gamma_per_s, 402.62180659503076, kRoundoff * 403.0);
  EXPECT_NEAR(k.mu_per_kgm2, 136.99127906976744, kRoundoff * 137.0);
}

TEST(MotorParameters, CurrentFedConstantsOfThePaperMotor) {
  const CurrentFedConstants k = derive_current_fed(kPaper000);
  EXPECT_NEAR(k.sigma, 0.1392381298449613, kRoundoff);
  EXPECT_NEAR(k.zeta_per_H_s, 439.3023356965767, kRoundoff * 440.0);
  EXPECT_NEAR(k.gamma_per_s, 427.08886085859666, kRoundoff * 428.0);
}

// Identities that tie the two papers' constants together, on every test motor.
TEST(MotorParameters, PapersAgreeOnEveryMotor) {
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const MotorParameters& m = motor.parameters;
    const VoltageFedConstants k0 = derive_voltage_fed(m);
    const CurrentFedConstants k1 = derive_current_fed(m);
    EXPECT_NEAR(k1.sigma * m.Ls_H, k0.sigma_H, kRoundoff * k0.sigma_H);  // ls sigma = sigma_000
    EXPECT_DOUBLE_EQ(k1.eta_per_s, k0.alpha_per_s);                      // eta = alpha = Rr/Lr
    // gamma_001 = rs/(sigma ls) + rr/(sigma lr) exceeds gamma_000 by exactly alpha.
    EXPECT_NEAR(k1.gamma_per_s, k0.gamma_per_s + k0.alpha_per_s, kRoundoff * k1.gamma_per_s);
    EXPECT_NEAR(k0.beta_per_H * k0.sigma_H * m.Lr_H, m.Lm_H, kRoundoff * m.Lm_H);
    EXPECT_GT(k0.sigma_H, 0.0);
  }
}

TEST(MotorParameters, ValidMotorsPass) {
  for (const auto& motor : test::test_motors()) {
    EXPECT_FALSE(find_invalid_parameter(motor.parameters).has_value()) << motor.name;
  }
  // The least leakage is a bound, not a band: 1.5e-3 passes.
  MotorParameters m = kPaper000;
  m.Ls_H = m.Lr_H = 0.5;
  m.Lm_H = 0.5 * std::sqrt(1 - 1.5e-3);
  EXPECT_FALSE(find_invalid_parameter(m).has_value());
}

TEST(MotorParameters, EachRuleNamesItsKey) {
  struct Case {
    void (*mutate)(MotorParameters&);
    const char* key;
    const char* rule;
  };
  const Case cases[] = {
      {[](MotorParameters& m) { m.Rs_Ohm = 0.0; }, "Rs_Ohm", "must be > 0"},
      {[](MotorParameters& m) { m.Ls_H = -0.4; }, "Ls_H", "must be > 0"},
      {[](MotorParameters& m) { m.Lm_H = 0.0; }, "Lm_H", "must be > 0"},
      {[](MotorParameters& m) { m.Rr_Ohm = -1.0; }, "Rr_Ohm", "must be > 0"},
      {[](MotorParameters& m) { m.Lr_H = 0.0; }, "Lr_H", "must be > 0"},
      {[](MotorParameters& m) { m.J_kgm2 = -0.01; }, "J_kgm2", "must be > 0"},
      {[](MotorParameters& m) { m.pole_pairs = 0; }, "pole_pairs", "must be > 0"},
      {[](MotorParameters& m) { m.friction_Nms = -1e-3; }, "friction_Nms", "must be >= 0"},
      {[](MotorParameters& m) { m.Rs_Ohm = std::numeric_limits<double>::quiet_NaN(); }, "Rs_Ohm",
       "must be finite"},
      {[](MotorParameters& m) { m.friction_Nms = std::numeric_limits<double>::infinity(); },
       "friction_Nms", "must be finite"},
      {[](MotorParameters& m) { m.Lm_H = 0.41; }, "Lm_H",
       "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
      // Equality is rejected too: sigma would be exactly zero.
      {[](MotorParameters& m) { m.Ls_H = m.Lr_H = m.Lm_H = 0.5; }, "Lm_H",
       "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
      // No leakage at inductances whose squares overflow float, or underflow it: the rule
      // compares ratios, so neither inf > inf nor 0 > 0 lets them through.
      {[](MotorParameters& m) { m.Ls_H = m.Lr_H = m.Lm_H = 2e19; }, "Lm_H",
       "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
      {[](MotorParameters& m) { m.Ls_H = m.Lr_H = m.Lm_H = 1e-23; }, "Lm_H",
       "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
      // A leakage factor of 5e-4, half the least one: a rounding away from none.
      {[](MotorParameters& m) { m.Ls_H = m.Lr_H = 0.5, m.Lm_H = 0.5 * std::sqrt(1 - 5e-4); },
       "Lm_H", "must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
  };
  for (const Case& c : cases) {
    MotorParameters m = kPaper000;
    c.mutate(m);
    const auto problem = find_invalid_parameter(m);
    ASSERT_TRUE(problem.has_value()) << c.key;
    EXPECT_EQ(problem->key, c.key);
    EXPECT_EQ(problem->rule, c.rule);
  }
}

}  // namespace
}  // namespace imd::control
