// The exact discretizations computed in float (control/float_discretization.cpp) against the
// double reference, on every test motor (0.55 kW to 37 kW, one to four pole pairs), at the
// sample periods 50 us, 100 us and 1 ms and at rotor resistances 0.5x to 2x. Each coefficient
// must be within the bound its header derives, relative to its own value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <utility>
#include <vector>

#include "control/current_fed_model.hpp"
#include "control/metzler_exponential.hpp"
#include "control/voltage_fed_model.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;  // float's u
const double kPeriods_s[] = {50e-6, 100e-6, 1e-3};
const double kRrFactors[] = {0.5, 0.75, 1.0, 1.5, 2.0};

double to_float(double x) {
  return double(float(x));
}

/// The motor with every parameter rounded to float: the float discretization then starts from
/// exactly the reference's numbers, and only its own rounding is measured.
MotorParameters float_exact(MotorParameters m) {
  m.Rs_Ohm = to_float(m.Rs_Ohm);
  m.Ls_H = to_float(m.Ls_H);
  m.Lm_H = to_float(m.Lm_H);
  m.Rr_Ohm = to_float(m.Rr_Ohm);
  m.Lr_H = to_float(m.Lr_H);
  m.J_kgm2 = to_float(m.J_kgm2);
  m.friction_Nms = to_float(m.friction_Nms);
  return m;
}

struct Named {
  const char* name;
  double VoltageFedCoefficients::*field;
};
const Named kVoltageFed[] = {
    {"a11", &VoltageFedCoefficients::a11},
    {"a12", &VoltageFedCoefficients::a12},
    {"a21", &VoltageFedCoefficients::a21},
    {"a22", &VoltageFedCoefficients::a22},
    {"b1", &VoltageFedCoefficients::b1},
    {"b2", &VoltageFedCoefficients::b2},
    {"eta1", &VoltageFedCoefficients::eta1},
    {"eta2", &VoltageFedCoefficients::eta2},
    {"eta3", &VoltageFedCoefficients::eta3},
    {"kappa1", &VoltageFedCoefficients::kappa1},
    {"kappa2", &VoltageFedCoefficients::kappa2},
    {"kappa3", &VoltageFedCoefficients::kappa3},
    {"omega_decay", &VoltageFedCoefficients::omega_decay},
    {"omega_decay_minus_one", &VoltageFedCoefficients::omega_decay_minus_one},
    {"omega_to_theta_s", &VoltageFedCoefficients::omega_to_theta_s},
    {"load_to_omega", &VoltageFedCoefficients::load_to_omega},
    {"load_to_theta", &VoltageFedCoefficients::load_to_theta},
};

/// The header's bound in units of u: 2^s 80 + (2 theta_0 + 4) eta_in + 8 with s and theta_0
/// the largest of the exponentials' and eta_in the generator's relative rounding (in u).
double voltage_fed_bound_u(const MotorParameters& m, double delta_s, double eta_in_u) {
  const VoltageFedFloatGenerators g = voltage_fed_float_generators(m, delta_s);
  const double theta0 = std::max(double(metzler_shifted_norm<float, 3>(g.axis, 0.0f)),
                                 double(metzler_shifted_norm<float, 3>(g.compound, g.friction)));
  const int s = std::max(metzler_squarings<float, 3>(g.axis, 0.0f),
                         metzler_squarings<float, 3>(g.compound, g.friction));
  return std::ldexp(80.0, s) + (2.0 * theta0 + 4.0) * eta_in_u + 8.0;
}

/// Per coefficient, the case closest to its bound (error and bound in u), printed for
/// docs/derivations.md.
struct Worst {
  std::vector<double> error_u = std::vector<double>(std::size(kVoltageFed), 0.0);
  std::vector<double> bound_u = std::vector<double>(std::size(kVoltageFed), 0.0);
  std::vector<double> max_u = std::vector<double>(std::size(kVoltageFed), 0.0);  ///< any case
  /// The bound of the case with the largest error.
  std::vector<double> bound_at_max_u = std::vector<double>(std::size(kVoltageFed), 0.0);
  double smallest_bound_u = INFINITY, largest_bound_u = 0.0;  ///< over the cases
};

void check_voltage_fed(const MotorParameters& m, double delta_s, double eta_in_u,
                       const std::string& label, Worst& worst) {
  const VoltageFedCoefficients ref = discretize_voltage_fed(m, to_float(delta_s));
  const VoltageFedCoefficients f = discretize_voltage_fed<float>(m, delta_s);
  const double bound_u = voltage_fed_bound_u(m, delta_s, eta_in_u);
  worst.smallest_bound_u = std::min(worst.smallest_bound_u, bound_u);
  worst.largest_bound_u = std::max(worst.largest_bound_u, bound_u);
  for (std::size_t i = 0; i < std::size(kVoltageFed); ++i) {
    const double r = ref.*kVoltageFed[i].field, v = f.*kVoltageFed[i].field;
    if (r == 0.0) {  // no friction: the exact zero must come out as zero
      EXPECT_EQ(v, 0.0) << label << " " << kVoltageFed[i].name;
      continue;
    }
    const double error_u = std::abs(v - r) / std::abs(r) / kUnitRoundoff;
    EXPECT_LE(error_u, bound_u) << label << " " << kVoltageFed[i].name << " float " << v
                                << " double " << r;
    if (error_u >= worst.max_u[i]) {
      worst.max_u[i] = error_u;
      worst.bound_at_max_u[i] = bound_u;
    }
    if (error_u / bound_u > worst.error_u[i] / std::max(worst.bound_u[i], 1.0)) {
      worst.error_u[i] = error_u;  // the case closest to its bound
      worst.bound_u[i] = bound_u;
    }
  }
}

void print(const char* title, const Worst& worst) {
  std::printf("%s bound %.1f u to %.1f u over the cases\n", title, worst.smallest_bound_u,
              worst.largest_bound_u);
  for (std::size_t i = 0; i < std::size(kVoltageFed); ++i) {
    std::printf("  %-22s largest error %5.1f u (bound %6.1f u); closest to its bound: %5.1f u "
                "of %6.1f u\n",
                kVoltageFed[i].name, worst.max_u[i], worst.bound_at_max_u[i], worst.error_u[i],
                worst.bound_u[i]);
  }
}

// The method itself, in double, against a general exponential of the full 9x9 matrix in long
// double (Eigen's MatrixFunctions): norm-wise within about 1e-19, so within 1e-13 of the
// smallest entries compared (near 1e-6 of their block). In double the Metzler method's
// truncation dominates: 1.1e-11 of each entry at most (its header, 12 terms), plus its
// rounding 2^s 80 u with s <= 5 and u = 2^-53, 3e-13. This checks the truncation argument that
// the float bound relies on (there 2e-4 u).
constexpr double kDoubleMethodTolerance = 1.1e-11 + 3e-13 + 1e-13;
TEST(FloatDiscretization, MetzlerMethodInDoubleMatchesAGeneralExponentialEntryByEntry) {
  using Matrix9l = Eigen::Matrix<long double, 9, 9>;
  for (const test::TestMotor& motor : test::test_motors()) {
    for (const double rr : kRrFactors) {
      MotorParameters m = motor.parameters;
      m.Rr_Ohm *= rr;
      for (const double delta_s : kPeriods_s) {
        const Eigen::Matrix3d axis = voltage_fed_axis_generator(m) * delta_s;
        const double g = -m.friction_Nms / m.J_kgm2 * delta_s;
        for (const auto& [x, gx] : {std::pair{axis, 0.0}, std::pair{additive_compound(axis), g}}) {
          Matrix9l big = Matrix9l::Zero();
          big.block<3, 3>(0, 0) = x.cast<long double>();
          big.block<3, 3>(0, 3).setIdentity();
          big.block<3, 3>(3, 3) =
              static_cast<long double>(gx) * Eigen::Matrix3<long double>::Identity();
          big.block<3, 3>(3, 6).setIdentity();
          const Matrix9l ref = big.exp();
          const MetzlerExponential<double, 3> r = metzler_block_exponential<double, 3>(x, gx);
          const auto check = [&](const Eigen::Matrix3d& value, int column, const char* block) {
            for (int i = 0; i < 3; ++i) {
              for (int j = 0; j < 3; ++j) {
                const double reference = double(ref(i, column + j));
                EXPECT_NEAR(value(i, j), reference, kDoubleMethodTolerance * std::abs(reference))
                    << motor.name << " Rr x" << rr << " delta " << delta_s << " " << block << "("
                    << i << "," << j << ")";
              }
            }
          };
          check(r.e_x, 0, "E");
          check(r.y, 3, "Y");
          check(r.z, 6, "Z");
          EXPECT_NEAR(r.e_g, double(ref(3, 3)), kDoubleMethodTolerance * double(ref(3, 3)));
          EXPECT_NEAR(r.w, double(ref(3, 6)), kDoubleMethodTolerance * double(ref(3, 6)));
        }
      }
    }
  }
}

// Float-exact parameters: the generator's entries are quotients, products and sums of
// positive terms of exact inputs, each within 9 u (header).
TEST(FloatDiscretization, VoltageFedWithinItsBoundOnEveryMotor) {
  Worst worst;
  for (const test::TestMotor& motor : test::test_motors()) {
    for (const double rr : kRrFactors) {
      MotorParameters m = motor.parameters;
      m.Rr_Ohm *= rr;
      m = float_exact(m);
      for (const double delta_s : kPeriods_s) {
        check_voltage_fed(
            m, delta_s, 9.0,
            motor.name + " Rr x" + std::to_string(rr) + " delta " + std::to_string(delta_s), worst);
      }
    }
  }
  print("float discretization, float-exact parameters:", worst);
}

// Parameters as the records hold them (double): rounding each to float (u) moves sigma Lr =
// Ls Lr - Lm^2 by its conditioning kappa = Ls Lr / (Ls Lr - Lm^2) times 2 u, and beta, 1/sigma
// and gamma with it; the other parameters' rounding adds 3 u: eta_in = 12 u + 2 kappa u.
TEST(FloatDiscretization, VoltageFedFromDoubleParametersWithinTheConditionedBound) {
  Worst worst;
  for (const test::TestMotor& motor : test::test_motors()) {
    for (const double rr : kRrFactors) {
      MotorParameters m = motor.parameters;
      m.Rr_Ohm *= rr;
      const double kappa = m.Ls_H * m.Lr_H / (m.Ls_H * m.Lr_H - m.Lm_H * m.Lm_H);
      for (const double delta_s : kPeriods_s) {
        check_voltage_fed(
            m, delta_s, 12.0 + 2.0 * kappa,
            motor.name + " Rr x" + std::to_string(rr) + " delta " + std::to_string(delta_s), worst);
      }
    }
  }
  print("float discretization, double parameters:", worst);
}

// Current-fed: every coefficient is a few operations (<= 12 u, expf and expm1f within 1 ulp),
// times the conditioning of its last difference (header).
TEST(FloatDiscretization, CurrentFedWithinItsBoundOnEveryMotor) {
  std::vector<std::pair<const char*, double>> largest_u;  // per coefficient, printed
  for (const test::TestMotor& motor : test::test_motors()) {
    for (const double rr : kRrFactors) {
      MotorParameters m = motor.parameters;
      m.Rr_Ohm *= rr;
      m = float_exact(m);
      for (const double t0_s : kPeriods_s) {
        const CurrentFedCoefficients ref = discretize_current_fed(m, to_float(t0_s));
        const CurrentFedCoefficients f = discretize_current_fed<float>(m, t0_s);
        const CurrentFedConstants k = derive_current_fed(m);
        const double a = m.friction_Nms / m.J_kgm2;
        const double decay_m1 = std::expm1(-k.eta_per_s * to_float(t0_s));
        const struct {
          const char* name;
          double value, reference, conditioning;
        } checks[] = {
            {"flux_decay", f.flux_decay, ref.flux_decay, 1.0},
            {"flux_from_i_now_H", f.flux_from_i_now_H, ref.flux_from_i_now_H,
             (k.sigma + std::abs(decay_m1)) / std::abs(k.sigma + decay_m1)},
            {"flux_from_i_next_H", f.flux_from_i_next_H, ref.flux_from_i_next_H, 1.0},
            {"torque_per_flux_A", f.torque_per_flux_A, ref.torque_per_flux_A, 1.0},
            {"eta_per_s", f.eta_per_s, ref.eta_per_s, 1.0},
            {"speed_decay", f.speed_decay, ref.speed_decay, 1.0},
            {"speed_decay_minus_one", f.speed_decay_minus_one, ref.speed_decay_minus_one, 1.0},
            {"torque_to_speed", f.torque_to_speed, ref.torque_to_speed,
             (k.eta_per_s + a) / (k.eta_per_s - a)},
            {"load_to_speed", f.load_to_speed, ref.load_to_speed, 1.0},
        };
        for (const auto& c : checks) {
          if (c.reference == 0.0) {
            EXPECT_EQ(c.value, 0.0) << motor.name << " " << c.name;
            continue;
          }
          const double error = std::abs(c.value - c.reference) / std::abs(c.reference);
          EXPECT_LE(error, 12.0 * c.conditioning * kUnitRoundoff)
              << motor.name << " Rr x" << rr << " T0 " << t0_s << " " << c.name;
          const auto named = std::find_if(largest_u.begin(), largest_u.end(),
                                          [&](const auto& e) { return e.first == c.name; });
          if (named == largest_u.end()) {
            largest_u.emplace_back(c.name, error / kUnitRoundoff);
          } else {
            named->second = std::max(named->second, error / kUnitRoundoff);
          }
        }
      }
    }
  }
  std::printf("current-fed float discretization, float-exact parameters:\n");
  for (const auto& [name, error_u] : largest_u) {
    std::printf("  %-22s largest error %5.1f u\n", name, error_u);
  }
}

}  // namespace
}  // namespace imd::control
