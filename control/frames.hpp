#pragma once
/// Two-axis vectors and the rotations between the stationary (alpha-beta) frame and the frame
/// aligned with the electrical rotor position (called AB, as in paper 001; paper 000 marks the
/// same quantities with a tilde). Tick context: all functions are noexcept and allocation-free.
#include <Eigen/Core>
#include <cmath>

#include "control/sin_cos.hpp"

namespace imd::control {

template <typename T>
using Vec2 = Eigen::Matrix<T, 2, 1>;

/// a^T J b with J = [[0, -1], [1, 0]], the skew product the papers write I^T J Phi.
template <typename T>
constexpr T dot_J(const Vec2<T>& a, const Vec2<T>& b) noexcept {
  return a.y() * b.x() - a.x() * b.y();
}

/// Whether every value is finite, in one test instead of one per value: x * 0 is zero for a
/// finite x and NaN for an infinite or NaN one, and a sum of zeros is zero, so the sum is finite
/// exactly when every value is.
template <typename T, typename... Rest>
bool all_finite(T first, Rest... rest) noexcept {
  return std::isfinite(first * T(0) + (T(0) + ... + (rest * T(0))));
}

/// J x: the vector turned by +90 degrees.
template <typename T>
Vec2<T> J_times(const Vec2<T>& x) noexcept {
  return Vec2<T>(-x.y(), x.x());
}

/// The rotation e^{angle J}, stored as cosine and sine so that one evaluation of the
/// trigonometric functions serves both directions.
template <typename T>
struct Rotation {
  T cos_angle = T(1);
  T sin_angle = T(0);

  static Rotation from_angle(T angle_rad) noexcept {
    const CosSin<T> cs = cos_sin(angle_rad);
    return {cs.cos, cs.sin};
  }
  /// e^{angle J} x: from the rotor-aligned frame to the stationary frame.
  Vec2<T> apply(const Vec2<T>& x) const noexcept {
    return Vec2<T>(cos_angle * x.x() - sin_angle * x.y(), sin_angle * x.x() + cos_angle * x.y());
  }
  /// e^{-angle J} x: from the stationary frame to the rotor-aligned frame.
  Vec2<T> apply_inverse(const Vec2<T>& x) const noexcept {
    return Vec2<T>(cos_angle * x.x() + sin_angle * x.y(), -sin_angle * x.x() + cos_angle * x.y());
  }
};

}  // namespace imd::control
