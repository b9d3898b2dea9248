// Clarke transforms, SVPWM and the feasible-input disk.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "control/input_disk.hpp"
#include "control/svpwm.hpp"

namespace imd::control {
namespace {

// Tolerances in this file: a few operations on values of order 1e2 round to ~1e-14 absolute;
// 1e-12 (values ~1e1) and 1e-9 (values ~3e2, through sqrt and division) leave wide margins
// while any error in a formula is of the order of the values themselves.

TEST(Clarke, RoundTripAndAmplitudeInvariance) {
  const Vec2<double> u(120.0, -35.0);
  const auto abc = inverse_clarke(u);
  EXPECT_NEAR(abc[0] + abc[1] + abc[2], 0.0, 1e-12);
  EXPECT_NEAR((clarke(abc) - u).norm(), 0.0, 1e-12);
  // A balanced set of peak 10 gives a vector of magnitude 10 (amplitude-invariant).
  const double a = 0.3;
  const PhaseValues<double> balanced{10 * std::cos(a), 10 * std::cos(a - 2 * std::numbers::pi / 3),
                                     10 * std::cos(a + 2 * std::numbers::pi / 3)};
  EXPECT_NEAR(clarke(balanced).norm(), 10.0, 1e-12);
}

/// Average phase-to-neutral voltages of an inverter with these duties, as alpha-beta.
Vec2<double> average_output(const PhaseValues<double>& duty, double v_bus_V) {
  return clarke(PhaseValues<double>{duty[0] * v_bus_V, duty[1] * v_bus_V, duty[2] * v_bus_V});
}

TEST(Svpwm, ReproducesTheVectorUpToTheLinearLimit) {
  const double v_bus = 311.0, limit = v_bus / std::sqrt(3.0);
  for (int i = 0; i < 360; i += 7) {
    const double angle = i * std::numbers::pi / 180;
    const Vec2<double> u = 0.999 * limit * Vec2<double>(std::cos(angle), std::sin(angle));
    const auto result = svpwm(u, v_bus);
    EXPECT_FALSE(result.clipped);
    for (double d : result.duty) {
      EXPECT_GE(d, 0.0);
      EXPECT_LE(d, 1.0);
    }
    EXPECT_NEAR((average_output(result.duty, v_bus) - u).norm(), 0.0, 1e-9);
  }
}

// Below 1 - 1e-5 of the linear radius the duties are left unclamped (control/svpwm.hpp): in
// float, over buses from 12 V to 1 kV, every direction (0.05 degree apart) and radii from
// 0.99999 to just under the unclamped range's edge, and at the edge itself, every duty lies in
// [0, 1] (the margin, 5e-6 of a duty, against float's rounding of a few 2^-24).
TEST(Svpwm, FloatDutiesStayInRangeWithoutTheClampInsideTheLinearRange) {
  for (const float v_bus : {12.0f, 48.0f, 311.0f, 540.0f, 1000.0f}) {
    const float limit = svpwm_linear_limit_V(v_bus);
    for (int i = 0; i < 7200; ++i) {
      const double angle = i * std::numbers::pi / 3600;
      for (const double radius : {0.99999, 1 - 1.00001e-5, 1 - 1e-5, 1 - 0.99999e-5, 1.0}) {
        const Vec2<float> u(float(radius * limit * std::cos(angle)),
                            float(radius * limit * std::sin(angle)));
        const auto result = svpwm(u, v_bus);
        for (float d : result.duty) {
          ASSERT_GE(d, 0.0f) << v_bus << " V, " << angle << " rad, " << radius;
          ASSERT_LE(d, 1.0f) << v_bus << " V, " << angle << " rad, " << radius;
        }
      }
    }
  }
}

TEST(Svpwm, ClipsBeyondTheLimitAndRejectsNonsense) {
  const double v_bus = 311.0, limit = v_bus / std::sqrt(3.0);
  const auto big = svpwm(Vec2<double>(400.0, 0.0), v_bus);
  EXPECT_TRUE(big.clipped);
  EXPECT_NEAR(average_output(big.duty, v_bus).norm(), limit, 1e-9);
  const auto nan = svpwm(Vec2<double>(std::nan(""), 0.0), v_bus);
  EXPECT_TRUE(nan.clipped);
  for (double d : nan.duty) EXPECT_EQ(d, 0.5);
  const auto no_bus = svpwm(Vec2<double>(10.0, 0.0), 0.0);
  EXPECT_TRUE(no_bus.clipped);
  for (double d : no_bus.duty) EXPECT_EQ(d, 0.5);
}

TEST(InputDisk, InscribedDiskLiesInBothAndTouchesBoth) {
  const InputDisk<double> voltage{{10.0, 0.0}, 100.0}, current{{120.0, 30.0}, 60.0};
  const auto lens = inscribed_disk(voltage, current);
  const double s = (current.center_V - voltage.center_V).norm();
  EXPECT_NEAR(lens.radius_V, (100.0 + 60.0 - s) / 2, 1e-12);
  // Contained in both, and tangent to both boundaries.
  EXPECT_NEAR((lens.center_V - voltage.center_V).norm() + lens.radius_V, 100.0, 1e-9);
  EXPECT_NEAR((lens.center_V - current.center_V).norm() + lens.radius_V, 60.0, 1e-9);
}

TEST(InputDisk, NestedDisjointAndUnlimitedCases) {
  const InputDisk<double> big{{0.0, 0.0}, 100.0}, small{{10.0, 0.0}, 5.0}, far{{300.0, 0.0}, 5.0};
  EXPECT_EQ(inscribed_disk(big, small).radius_V, 5.0);
  EXPECT_EQ(inscribed_disk(small, big).radius_V, 5.0);
  const auto apart = inscribed_disk(big, far);  // no common point: the nearest point of `big`
  EXPECT_EQ(apart.radius_V, 0.0);
  EXPECT_NEAR((apart.center_V - Vec2<double>(100.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(inscribed_disk(InputDisk<double>{}, small).radius_V, 5.0);
  EXPECT_TRUE(InputDisk<double>{}.unlimited());
  EXPECT_EQ(big.clamp({200.0, 0.0}), Vec2<double>(100.0, 0.0));
}

TEST(InputDisk, NanRadiusAllowsOnlyTheCentre) {
  // A NaN limit (a broken bus reading) must not read as "no limit".
  const InputDisk<double> broken{{5.0, 1.0}, std::nan("")};
  EXPECT_FALSE(broken.unlimited());
  EXPECT_EQ(broken.clamp({300.0, 0.0}), Vec2<double>(5.0, 1.0));
  EXPECT_FALSE(broken.contains({300.0, 0.0}));
}

TEST(InputDisk, ContainsComparesTheSquaredDistanceAsTheDistance) {
  // contains() compares |v - c|^2 with (r + tolerance)^2: the same answer as |v - c| <= r +
  // tolerance for every point off the circle by more than the rounding of the two sides, a few
  // ulp of r^2 taken back to a distance: ~1e-13 V in double and ~1e-5 V in float at r = 250 V
  // (points nearer than 1e-9 V and 1e-3 V are left out).
  const InputDisk<double> disk{{3.0, -2.0}, 250.0};
  const InputDisk<float> disk_f{{3.0f, -2.0f}, 250.0f};
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const double angle = 0.0031 * i, reach = 180.0 + 0.05 * i;  // through the edge at 250 V
    const Vec2<double> v = disk.center_V + reach * Vec2<double>(std::cos(angle), std::sin(angle));
    for (const double tolerance : {0.0, -0.25, 1.0}) {
      const double bound = disk.radius_V + tolerance;
      if (std::abs((v - disk.center_V).norm() - bound) < 1e-9) continue;
      EXPECT_EQ(disk.contains(v, tolerance), (v - disk.center_V).norm() <= bound) << i;
      const Vec2<float> vf = v.cast<float>();
      if (std::abs((vf - disk_f.center_V).norm() - float(bound)) < 1e-3f) continue;  // float ulp
      EXPECT_EQ(disk_f.contains(vf, float(tolerance)), (vf - disk_f.center_V).norm() <= bound);
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
  // A negative bound contains nothing, not even the centre; a zero radius only the centre.
  EXPECT_FALSE(disk.contains(disk.center_V, -300.0));
  const InputDisk<double> point{{1.0, 1.0}, 0.0};
  EXPECT_TRUE(point.contains({1.0, 1.0}));
  EXPECT_FALSE(point.contains({1.0, 1.0 + 1e-9}));
}

}  // namespace
}  // namespace imd::control
