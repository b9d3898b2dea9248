#pragma once
/// Clarke transforms (amplitude-invariant) and space-vector PWM with min-max zero-sequence
/// injection. The linear range is |u_alphabeta| <= v_bus / sqrt(3). Tick context.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "control/frames.hpp"

namespace imd::control {

template <typename T>
using PhaseValues = std::array<T, 3>;  ///< phases a, b, c

/// 1/sqrt(3) and 1/3, rounded once: the transforms multiply by them rather than divide (a
/// division takes 14 cycles on the Cortex-M4F, a multiplication one).
template <typename T>
inline constexpr T kInvSqrt3 = std::numbers::inv_sqrt3_v<T>;
template <typename T>
inline constexpr T kOneThird = T(1) / T(3);

/// alpha-beta from three phase values (their zero-sequence part is dropped).
template <typename T>
Vec2<T> clarke(const PhaseValues<T>& abc) noexcept {
  return Vec2<T>((T(2) * abc[0] - abc[1] - abc[2]) * kOneThird<T>,
                 (abc[1] - abc[2]) * kInvSqrt3<T>);
}

/// Phase values (without zero sequence) from alpha-beta.
template <typename T>
PhaseValues<T> inverse_clarke(const Vec2<T>& ab) noexcept {
  const T half_sqrt3 = T(std::numbers::sqrt3 / 2);
  return {ab.x(), -ab.x() / T(2) + half_sqrt3 * ab.y(), -ab.x() / T(2) - half_sqrt3 * ab.y()};
}

/// Largest voltage-vector magnitude SVPWM produces without distortion.
template <typename T>
T svpwm_linear_limit_V(T v_bus_V) noexcept {
  return v_bus_V * kInvSqrt3<T>;
}

template <typename T>
struct SvpwmResult {
  PhaseValues<T> duty{T(0.5), T(0.5), T(0.5)};  ///< high-side on-time fractions, in [0, 1]
  bool clipped = false;                         ///< the request exceeded the linear range
};

/// Duties that make the average phase-to-neutral voltages equal to u (alpha-beta), with the
/// zero sequence centring the phases. Beyond the linear range the vector is scaled down to it
/// (direction kept). A non-positive or NaN bus gives 50 % duties and `clipped`.
template <typename T>
SvpwmResult<T> svpwm(Vec2<T> u_alphabeta_V, T v_bus_V) noexcept {
  SvpwmResult<T> result;
  if (!(v_bus_V > T(0))) {
    result.clipped = true;
    return result;
  }
  const T limit = svpwm_linear_limit_V(v_bus_V);
  const T magnitude2 = u_alphabeta_V.squaredNorm();
  // Compared squared: the square root only for a vector to scale down.
  if (!(magnitude2 <= limit * limit)) {  // also catches NaN
    result.clipped = true;
    const T magnitude = u_alphabeta_V.norm();
    u_alphabeta_V =
        magnitude > limit ? Vec2<T>(u_alphabeta_V * (limit / magnitude)) : Vec2<T>::Zero();
  }
  const PhaseValues<T> v = inverse_clarke(u_alphabeta_V);
  const T offset = -(std::max({v[0], v[1], v[2]}) + std::min({v[0], v[1], v[2]})) / T(2);
  const T per_bus = T(1) / v_bus_V;  // one division for the three phases
  // The duties span 0.5 -/+ (max - min) / (2 v_bus), and max - min <= sqrt(3) |u|: inside the
  // linear range by 1e-5 of its radius they lie inside [0, 1] by 5e-6, far beyond their
  // rounding (a few 2^-24). Only nearer the edge may rounding put one outside: clamped there.
  for (int phase = 0; phase < 3; ++phase) {
    result.duty[phase] = T(0.5) + (v[phase] + offset) * per_bus;
  }
  if (!(magnitude2 <= T(1 - 2e-5) * (limit * limit))) {
    for (T& duty : result.duty) duty = std::clamp(duty, T(0), T(1));
  }
  return result;
}

}  // namespace imd::control
