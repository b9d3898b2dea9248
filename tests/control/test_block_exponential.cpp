// The structured exponential of control/block_exponential.hpp against a general one: Eigen's
// MatrixFunctions applied to the full 9x9 matrix, in long double so that the reference's own
// rounding is far below the tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "control/block_exponential.hpp"
#include "control/voltage_fed_model.hpp"
#include "test_motors.hpp"

namespace imd::control {
namespace {

using Matrix9l = Eigen::Matrix<long double, 9, 9>;

Matrix9l reference(const Eigen::Matrix3d& x, double g) {
  Matrix9l big = Matrix9l::Zero();
  big.block<3, 3>(0, 0) = x.cast<long double>();
  big.block<3, 3>(0, 3).setIdentity();
  big.block<3, 3>(3, 3) = static_cast<long double>(g) * Eigen::Matrix3<long double>::Identity();
  big.block<3, 3>(3, 6).setIdentity();
  return big.exp();
}

/// Largest entry error of each block, relative to the block's largest entry (the error bound
/// of the header is relative to the blocks' size).
double worst_block_error(const BlockExponential<double>& r, const Matrix9l& e) {
  const auto block_error = [](const Eigen::Matrix3d& value, const Eigen::Matrix3<long double>& ref) {
    const long double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300L);
    return static_cast<double>((value.cast<long double>() - ref).cwiseAbs().maxCoeff() / scale);
  };
  const long double e_g = e(3, 3), w = e(3, 6);
  return std::max({block_error(r.e_x, e.block<3, 3>(0, 0)), block_error(r.y, e.block<3, 3>(0, 3)),
                   block_error(r.z, e.block<3, 3>(0, 6)),
                   static_cast<double>(std::abs((r.e_g - e_g) / e_g)),
                   static_cast<double>(std::abs((r.w - w) / w))});
}

// The header's rounding estimate, (1 + 4 theta) x 8 ulp of the blocks' size with
// theta = |X| + |g| (the scaling halves until theta/2^s <= 1/4; each squaring about doubles
// the error and adds its own). An estimate, checked here over the range the drive uses and
// beyond it to theta = 8; the header says where it stops holding.
double tolerance(const Eigen::Matrix3d& x, double g, double ulp) {
  const double theta = x.cwiseAbs().rowwise().sum().maxCoeff() + std::abs(g);
  return (1.0 + 4.0 * theta) * 8.0 * ulp;
}
constexpr double kDoubleUlp = 2.2e-16;
constexpr double kFloatUlp = 1.2e-7;

TEST(BlockExponential, MatchesTheFullExponentialOnTheMotorsOverEveryPeriod) {
  // The matrices the voltage-fed model exponentiates, from 10 us to 10 ms.
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const Eigen::Matrix3d a3 = voltage_fed_axis_generator(motor.parameters);
    const double f = motor.parameters.friction_Nms / motor.parameters.J_kgm2;
    for (const double delta_s : {1e-5, 5e-5, 1e-4, 1e-3, 1e-2}) {
      SCOPED_TRACE(delta_s);
      const Eigen::Matrix3d m = additive_compound(a3) * delta_s;
      const double g = -f * delta_s;
      EXPECT_LT(worst_block_error(block_exponential<double>(m, g), reference(m, g)),
                tolerance(m, g, kDoubleUlp));
      const Eigen::Matrix3d e = a3 * delta_s;
      EXPECT_LT(worst_block_error(block_exponential<double>(e, 0.0), reference(e, 0.0)),
                tolerance(e, 0.0, kDoubleUlp));
    }
  }
}

TEST(BlockExponential, MatchesTheFullExponentialOnRandomMatrices) {
  // General 3x3 blocks, not only the motors' stable ones: eigenvalues of either sign, norms
  // from 1e-3 (no squaring) to 8 (five squarings), g of either sign.
  std::mt19937_64 rng(20261125);
  std::normal_distribution<double> entry(0.0, 1.0);
  for (const double norm : {1e-3, 0.1, 0.25, 1.0, 3.0, 8.0}) {
    for (int draw = 0; draw < 200; ++draw) {
      Eigen::Matrix3d x;
      for (int i = 0; i < 9; ++i) x(i / 3, i % 3) = entry(rng);
      x *= norm / x.cwiseAbs().rowwise().sum().maxCoeff();
      const double g = 0.5 * norm * entry(rng);
      EXPECT_LT(worst_block_error(block_exponential<double>(x, g), reference(x, g)),
                tolerance(x, g, kDoubleUlp))
          << "norm " << norm << " draw " << draw;
    }
  }
}

TEST(BlockExponential, FloatStaysWithinItsOwnRounding) {
  // The same bound in float's ulp, plus the rounding of the input to float: one ulp of X,
  // amplified by the condition of the exponential (about theta), inside the bound's 8 ulp.
  for (const auto& motor : test::test_motors()) {
    SCOPED_TRACE(motor.name);
    const Eigen::Matrix3d a3 = voltage_fed_axis_generator(motor.parameters);
    const double f = motor.parameters.friction_Nms / motor.parameters.J_kgm2;
    for (const double delta_s : {5e-5, 1e-4, 1e-3}) {
      const Eigen::Matrix3d m = additive_compound(a3) * delta_s;
      const BlockExponential<float> r =
          block_exponential<float>(m.cast<float>(), static_cast<float>(-f * delta_s));
      BlockExponential<double> widened;
      widened.e_x = r.e_x.cast<double>();
      widened.y = r.y.cast<double>();
      widened.z = r.z.cast<double>();
      widened.e_g = r.e_g;
      widened.w = r.w;
      EXPECT_LT(worst_block_error(widened, reference(m, -f * delta_s)),
                tolerance(m, -f * delta_s, kFloatUlp))
          << delta_s;
    }
  }
}

}  // namespace
}  // namespace imd::control
