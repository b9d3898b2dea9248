#pragma once
/// The cosine and sine of one angle, for the rotations of the tick.
///   double: the standard library's, so that the host's double runs keep their exactness.
///   float:  one range reduction and two minimax polynomials. newlib's sinf and cosf each reduce
///           the argument again and cost about four times as many instructions on the MCU,
///           where the tick evaluates two rotations per period.
/// The float version: Cody-Waite reduction by pi/2 with pi/2 split in three parts whose
/// products with the quadrant number are exact for |n| < 2^12, then Cephes' sinf/cosf
/// polynomials on [-pi/4, pi/4] (relative error below 1e-7 there). The result is within 2 ulp
/// of 1 of the exact values for |angle| <= 4096 rad (tests/control/test_sin_cos.cpp). Beyond
/// that the angle is first reduced exactly modulo float(2 pi) (fmodf): the error this adds,
/// |angle| / (2 pi) * |2 pi - float(2 pi)| = |angle| * 2.8e-8, is below half an ulp of the
/// float angle itself (|angle| * 6e-8), so no float argument is known better than that. Not
/// newlib's sinf and cosf: their exact large-argument reduction (__kernel_rem_pio2f and its
/// table) is 3.5 KB of the board image's flash. A non-finite angle gives NaN for both.
#include <cmath>
#include <cstdint>

namespace imd::control {

template <typename T>
struct CosSin {
  T cos, sin;
};

inline CosSin<double> cos_sin(double angle_rad) noexcept {
  return {std::cos(angle_rad), std::sin(angle_rad)};
}

inline CosSin<float> cos_sin(float angle_rad) noexcept {
  float x = angle_rad;
  if (!(std::fabs(x) <= 4096.0f)) [[unlikely]] {
    if (!std::isfinite(x)) return {x - x, x - x};  // NaN, as the standard library gives
    x = std::fmod(x, 6.28318548f);                  // exact; |x| < float(2 pi)
  }
  const auto n = static_cast<int32_t>(x * 0.636619772f + (x >= 0.0f ? 0.5f : -0.5f));
  const auto q = static_cast<float>(n);
  const float r = ((x - q * 1.5703125f) - q * 4.837512969970703125e-4f) -
                  q * 7.54978995489188216e-8f;  // x - n pi/2, |r| <= pi/4 (+ rounding)
  const float r2 = r * r;
  const float s =
      r + r * r2 * (-1.6666654611e-1f + r2 * (8.3321608736e-3f + r2 * -1.9515295891e-4f));
  const float c = 1.0f - 0.5f * r2 +
                  r2 * r2 *
                      (4.166664568298827e-2f + r2 * (-1.388731625493765e-3f +
                                                     r2 * 2.443315711809948e-5f));
  switch (n & 3) {
    case 0:
      return {c, s};
    case 1:
      return {-s, c};
    case 2:
      return {-c, -s};
    default:
      return {s, -c};
  }
}

}  // namespace imd::control
