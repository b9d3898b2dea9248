// The single-precision cosine and sine of the tick's rotations (control/sin_cos.hpp) against
// the exact values of the same float angle (computed in double).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "control/frames.hpp"
#include "control/sin_cos.hpp"

namespace imd::control {
namespace {

// The bound: Cephes' polynomials are within 1 ulp on [-pi/4, pi/4]; the three-part split of
// pi/2 makes the products n * part exact (8 + 12 and 19 + 12 significant bits for |n| < 2^12),
// so the reduction adds only the rounding of its two last subtractions, half an ulp each of a
// value below pi/4; the result rounds once more. Together below 2 ulp of 1 = 2^-22.
constexpr double kBound = 0x1p-22;

TEST(SinCos, FloatIsWithinTwoUlpOfOneOverTheRange) {
  double worst = 0.0;
  for (int i = -4'000'000; i <= 4'000'000; ++i) {
    const float angle = static_cast<float>(i) * 1.0239e-3f;  // -4095.6 .. 4095.6 rad
    const CosSin<float> cs = cos_sin(angle);
    const double exact_cos = std::cos(double(angle)), exact_sin = std::sin(double(angle));
    worst = std::max({worst, std::abs(cs.cos - exact_cos), std::abs(cs.sin - exact_sin)});
  }
  EXPECT_LE(worst, kBound);
  RecordProperty("worst_abs_error", std::to_string(worst));
}

TEST(SinCos, QuadrantBoundariesAndSigns) {
  for (int k = -64; k <= 64; ++k) {
    for (const float offset : {-1e-3f, 0.0f, 1e-3f}) {
      const float angle = static_cast<float>(k * M_PI / 4) + offset;
      const CosSin<float> cs = cos_sin(angle);
      EXPECT_NEAR(cs.cos, std::cos(double(angle)), kBound) << angle;
      EXPECT_NEAR(cs.sin, std::sin(double(angle)), kBound) << angle;
    }
  }
}

TEST(SinCos, NonFiniteAndHugeAnglesFallBackToTheStandardLibrary) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(std::isnan(cos_sin(nan).cos));  // the drive's non_finite check sees it
  EXPECT_TRUE(std::isnan(cos_sin(std::numeric_limits<float>::infinity()).sin));
  EXPECT_EQ(cos_sin(1e6f).cos, std::cos(1e6f));
  EXPECT_EQ(cos_sin(1e6f).sin, std::sin(1e6f));
}

TEST(SinCos, DoubleIsTheStandardLibrarys) {
  for (const double angle : {-7.0, -1.0, 0.0, 0.3, 2.5, 100.0}) {
    EXPECT_EQ(cos_sin(angle).cos, std::cos(angle));
    EXPECT_EQ(cos_sin(angle).sin, std::sin(angle));
    const Rotation<double> r = Rotation<double>::from_angle(angle);
    EXPECT_EQ(r.cos_angle, std::cos(angle));
  }
}

}  // namespace
}  // namespace imd::control
