// The single-precision angle of a vector (control/atan2.hpp) against the exact angle of the
// same float vector (computed in double).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "control/atan2.hpp"

namespace imd::control {
namespace {

// The bound, as a budget of the worst cases: the polynomial on the reduced argument, |atan| <=
// pi/8 there, with Cephes' peak relative error of atanf (1.9e-7, measured by Cephes, not
// proven), 7.5e-8 rad; the quotient's rounding, half an ulp of t <= 1, 3e-8 (atan's slope is at
// most 1); the reduction (t - 1) / (t + 1), three roundings of values up to 0.414, 7.4e-8; pi/4's
// float value and the addition 5e-8; pi/2 - a 1e-7; pi - a 2.1e-7. Together 5.4e-7 < 2^-20,
// which leaves room for the MCU, whose compiler may fuse the polynomial's steps (one rounding
// less each). The sweeps below are what checks it.
constexpr double kBound = 0x1p-20;

// The angle between two angles, in [0, pi] (for y = -0 the result is +pi where the exact one
// is -pi: the same direction).
double apart(double a, double b) {
  const double d = std::abs(a - b);
  return d > std::numbers::pi ? 2 * std::numbers::pi - d : d;
}

TEST(Atan2, FloatIsWithinTheBoundAllAroundAtEveryScale) {
  double worst = 0.0;
  for (int decade = -6; decade <= 6; ++decade) {
    const double radius = std::pow(10.0, decade);
    for (int i = 0; i < 200'000; ++i) {
      const double angle = std::numbers::pi * (2.0 * (i + 0.5) / 200'000 - 1.0);
      const float y = float(radius * std::sin(angle)), x = float(radius * std::cos(angle));
      const double error = apart(atan2_rad(y, x), std::atan2(double(y), double(x)));
      if (!(error <= worst)) worst = error;  // a NaN is kept, and fails the bound
    }
  }
  EXPECT_LE(worst, kBound);
  RecordProperty("worst_abs_error_rad", std::to_string(worst));
}

TEST(Atan2, OctantBoundariesAxesAndSigns) {
  for (int k = -8; k <= 8; ++k) {
    for (const double offset : {-1e-4, -1e-7, 0.0, 1e-7, 1e-4}) {
      const double angle = k * std::numbers::pi / 8 + offset;
      const float y = float(std::sin(angle)), x = float(std::cos(angle));
      EXPECT_LE(apart(atan2_rad(y, x), std::atan2(double(y), double(x))), kBound) << angle;
    }
  }
  EXPECT_EQ(atan2_rad(0.0f, 1.0f), 0.0f);
  EXPECT_NEAR(atan2_rad(1.0f, 0.0f), std::numbers::pi / 2, kBound);
  EXPECT_NEAR(atan2_rad(-1.0f, 0.0f), -std::numbers::pi / 2, kBound);
  EXPECT_NEAR(atan2_rad(0.0f, -1.0f), std::numbers::pi, kBound);
  EXPECT_NEAR(atan2_rad(-1e-30f, -1.0f), -std::numbers::pi, kBound);
}

TEST(Atan2, DegenerateAndNonFiniteVectors) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(atan2_rad(0.0f, 0.0f), 0.0f);  // no direction: the frame starts at the rotor's
  EXPECT_TRUE(std::isnan(atan2_rad(nan, 1.0f)));
  EXPECT_TRUE(std::isnan(atan2_rad(1.0f, nan)));
  EXPECT_TRUE(std::isnan(atan2_rad(nan, 0.0f)));  // beside a zero too
  EXPECT_TRUE(std::isnan(atan2_rad(0.0f, nan)));
  EXPECT_TRUE(std::isnan(atan2_rad(inf, inf)));
  EXPECT_NEAR(atan2_rad(inf, 1.0f), std::numbers::pi / 2, kBound);
  EXPECT_NEAR(atan2_rad(1.0f, -inf), std::numbers::pi, kBound);
}

TEST(Atan2, DoubleIsTheStandardLibrarys) {
  for (const double y : {-2.0, -0.5, 0.0, 0.3, 7.0}) {
    for (const double x : {-3.0, 0.0, 0.25, 9.0}) EXPECT_EQ(atan2_rad(y, x), std::atan2(y, x));
  }
}

}  // namespace
}  // namespace imd::control
