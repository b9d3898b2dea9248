// The encoder observer's gain in closed form (control/encoder_observer.hpp): it places the
// triple pole, agrees with Ackermann's formula evaluated in long double, loses no more in float
// than its roundings allow, and the quantization bounds computed in float stay bounds.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <vector>

#include "control/encoder_observer.hpp"
#include "control/voltage_fed_model.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

using Vec3L = Eigen::Matrix<long double, 3, 1>;
using Mat3L = Eigen::Matrix<long double, 3, 3>;

/// Each test motor, the same with 20x its inertia and with viscous friction (e < 0), at 10 and
/// 20 kHz: the cases the closed form's sign argument covers.
struct Case {
  std::string name;
  VoltageFedCoefficients c;
};
std::vector<Case> cases() {
  std::vector<Case> all;
  for (const test::TestMotor& motor : test::test_motors()) {
    MotorParameters heavy = motor.parameters, rubbing = motor.parameters;
    heavy.J_kgm2 *= 20.0;
    rubbing.friction_Nms += 0.05 * motor.parameters.J_kgm2 * 100.0;  // tau_mech = 0.2 s
    for (double delta_s : {1e-4, 5e-5}) {
      const std::string at = delta_s == 1e-4 ? " 10 kHz" : " 20 kHz";
      all.push_back({motor.name + at, discretize_voltage_fed(motor.parameters, delta_s)});
      all.push_back({motor.name + " heavy" + at, discretize_voltage_fed(heavy, delta_s)});
      all.push_back({motor.name + " friction" + at, discretize_voltage_fed(rubbing, delta_s)});
    }
  }
  return all;
}

Mat3L mechanics(const VoltageFedCoefficients& c) {
  Mat3L a;
  a << 1, c.omega_to_theta_s, c.load_to_theta, 0, c.omega_decay, c.load_to_omega, 0, 0, 1;
  return a;
}

/// Ackermann's formula in long double: the reference the closed form replaced.
Vec3L ackermann(const VoltageFedCoefficients& c, long double bandwidth_rad_s) {
  const Mat3L a = mechanics(c);
  const Eigen::Matrix<long double, 1, 3> ca = a.row(0);
  Mat3L observability;
  observability << ca, ca * a, ca * a * a;
  const long double z = std::exp(-bandwidth_rad_s * (long double)c.delta_s);
  const Mat3L shifted = a - z * Mat3L::Identity();
  return shifted * shifted * shifted * observability.inverse() * Vec3L(0, 0, 1);
}

TEST(EncoderObserverGain, PlacesTheTriplePoleOnEveryMotor) {
  for (const Case& k : cases()) {
    for (double bandwidth : {50.0, 400.0, 2000.0}) {
      const Eigen::Vector3d gain = place_encoder_observer(k.c, bandwidth);
      const Mat3L m = mechanics(k.c) - gain.cast<long double>() * mechanics(k.c).row(0);
      const long double p = std::exp(-(long double)bandwidth * k.c.delta_s);
      // The characteristic polynomial's coefficients (a triple root's eigenvalues are
      // ill-conditioned, its coefficients are not): trace 3p, principal minors 3p^2, det p^3.
      const long double minors = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0) + m(0, 0) * m(2, 2) -
                                 m(0, 2) * m(2, 0) + m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1);
      // The gain is good to a few double roundings, and each coefficient is a sum of products
      // of entries of order 1: 1e-13 is a hundred times that.
      EXPECT_NEAR(double(m.trace()), double(3 * p), 1e-13) << k.name << " " << bandwidth;
      EXPECT_NEAR(double(minors), double(3 * p * p), 1e-13) << k.name << " " << bandwidth;
      EXPECT_NEAR(double(m.determinant()), double(p * p * p), 1e-13) << k.name << " " << bandwidth;
    }
  }
}

TEST(EncoderObserverGain, EqualsAckermannsFormulaInLongDouble) {
  // Relative, gain by gain: the polynomial test above is absolute, and L3 (of order s^3) could
  // be off by 1e-5 of itself at 50 rad/s and still pass it.
  for (const Case& k : cases()) {
    for (double bandwidth : {50.0, 400.0, 2000.0}) {
      const Vec3L reference = ackermann(k.c, (long double)bandwidth);
      const Eigen::Vector3d gain = place_encoder_observer(k.c, bandwidth);
      for (int i = 0; i < 3; ++i) {
        // The observability matrix's condition number is 1e6 to 7e8 on the test motors (20x that
        // for the heavy ones): long double's inverse (unit roundoff 5.4e-20) is good to about
        // 5.4e-20 x 1.4e10 = 8e-10 at worst; 1e-8 is ten times that. Measured: 8.7e-15.
        EXPECT_NEAR(gain(i) / double(reference(i)), 1.0, 1e-8)
            << k.name << " " << bandwidth << " L" << i + 1;
      }
    }
  }
}

TEST(EncoderObserverGain, FloatLosesNoMoreThanItsRoundings) {
  // Five inputs rounded to float, expm1f within 2 ulp, and at most 14 operations along any
  // path: at most 21 roundings of 2^-24 each, relative, amplified by the numerators'
  // cancellation (control/encoder_observer.hpp) by at most 1.22 here (x = (c/J) / bandwidth
  // = 0.1 for the friction cases at 50 rad/s): 26 roundings. 32 of them is the tolerance.
  // Measured: 4.8.
  const double tolerance = 32 * std::ldexp(1.0, -24);
  for (const Case& k : cases()) {
    for (double bandwidth : {50.0, 400.0, 2000.0}) {
      const Eigen::Vector3d exact = place_encoder_observer(k.c, bandwidth);
      const Eigen::Vector3f single = place_encoder_observer<float>(k.c, float(bandwidth));
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(double(single(i)) / exact(i), 1.0, tolerance)
            << k.name << " " << bandwidth << " L" << i + 1;
      }
    }
  }
}

TEST(EncoderObserverGain, QuantizationBoundsInFloatStayBounds) {
  for (const Case& k : cases()) {
    const double q_rad = 2 * std::numbers::pi / 8192;
    const QuantizationErrorBounds exact = encoder_quantization_bounds(k.c, 400.0, q_rad);
    const QuantizationErrorBounds single =
        encoder_quantization_bounds<float>(k.c, 400.0f, float(q_rad));
    // Not below the double result (it is raised by its rounding bound, 3 terms epsilon), and
    // above it by no more than twice that raise (the sums' rounding may have gone up by as
    // much as it was raised for going down), plus the float gain's own 2e-6 (the test above).
    // At 20 kHz that is 2 x 1.1e-3; measured: the raise alone, within 3e-6.
    const double terms = 60.0 / (400.0 * k.c.delta_s) + 100;
    const double raise = 2 * 3 * terms * std::ldexp(1.0, -23) + 2e-6;
    EXPECT_GE(single.omega_rad_s, exact.omega_rad_s) << k.name;
    EXPECT_LE(single.omega_rad_s, exact.omega_rad_s * (1 + raise)) << k.name;
    EXPECT_GE(single.load_Nm, exact.load_Nm) << k.name;
    EXPECT_LE(single.load_Nm, exact.load_Nm * (1 + raise)) << k.name;
  }
}

}  // namespace
}  // namespace imd::control
