#pragma once
/// The angle of a vector, for the start of the field-oriented law (once, not per tick).
///   double: the standard library's, so that the host's double runs keep their exactness.
///   float:  the quotient of the smaller by the larger component, Cephes' atanf reduction and
///           polynomial on [0, tan(pi/8)], and the octant's offset. newlib's atan2f with the
///           atanf it calls is 756 B of the board image's flash; this, under half of that.
/// The float result is within 2^-20 rad of the exact angle of the float vector (the bound's
/// terms: tests/control/test_atan2.cpp). A zero vector gives 0; one infinite component beside a
/// finite one gives that axis's angle; a NaN or two infinite components give NaN.
#include <cmath>

namespace imd::control {

inline double atan2_rad(double y, double x) noexcept {
  return std::atan2(y, x);
}

inline float atan2_rad(float y, float x) noexcept {
  const float ay = std::fabs(y), ax = std::fabs(x);
  const float big = ay > ax ? ay : ax, small = ay > ax ? ax : ay;
  if (big == 0.0f) return small;  // +0 for a zero vector, NaN beside a NaN
  float t = small / big;          // in [0, 1]
  float offset = 0.0f;
  if (t > 0.414213562f) {  // tan(pi/8): atan t = pi/4 + atan((t - 1) / (t + 1))
    t = (t - 1.0f) / (t + 1.0f);
    offset = 0.785398163f;
  }
  const float z = t * t;
  const float a =
      offset + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z -
                 3.33329491539e-1f) *
                    z * t +
                t);
  const float octant = ay > ax ? 1.570796327f - a : a;           // the angle in [0, pi/2]
  const float half = x < 0.0f ? 3.141592654f - octant : octant;  // in [0, pi]
  return y < 0.0f ? -half : half;
}

}  // namespace imd::control
