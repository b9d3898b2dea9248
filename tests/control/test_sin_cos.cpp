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

TEST(SinCos, NonFiniteAnglesGiveNaN) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(std::isnan(cos_sin(nan).cos));  // the drive's non_finite check sees it
  EXPECT_TRUE(std::isnan(cos_sin(nan).sin));
  EXPECT_TRUE(std::isnan(cos_sin(inf).sin));
  EXPECT_TRUE(std::isnan(cos_sin(-inf).cos));
}

// Beyond 4096 rad the angle is reduced exactly modulo float(2 pi), which differs from 2 pi by
// d = 1.7485e-7: k = |angle| / (2 pi) turns shift the angle by k d = |angle| * 2.783e-8 (taken
// as 2.79e-8 to cover the rounding of k), then the reduced angle's own 2 ulp bound applies.
TEST(SinCos, HugeAnglesStayWithinTheReductionBound) {
  for (const float angle : {4096.5f, -5000.0f, 1e5f, -3.3e5f, 1e6f, 1.2345e7f}) {
    const CosSin<float> cs = cos_sin(angle);
    const double bound = std::abs(double(angle)) * 2.79e-8 + kBound;
    EXPECT_NEAR(cs.cos, std::cos(double(angle)), bound) << angle;
    EXPECT_NEAR(cs.sin, std::sin(double(angle)), bound) << angle;
  }
  // Where that bound exceeds 1 the result is still a point of the unit circle: cos and sin of
  // the reduced angle are each within kBound, so c^2 + s^2 is within 2 (|c| + |s|) kBound
  // <= 2 sqrt(2) kBound of 1, plus its own rounding; 4 kBound holds both.
  for (const float angle : {-8e9f, 3e20f, std::numeric_limits<float>::max()}) {
    const CosSin<float> cs = cos_sin(angle);
    EXPECT_NEAR(double(cs.cos) * cs.cos + double(cs.sin) * cs.sin, 1.0, 4 * kBound) << angle;
  }
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
