#pragma once
/// Durations in whole control periods (construction only, in the design arithmetic Real).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "control/real.hpp"

namespace imd::firmware {

/// `duration_s` in ticks of `period_s`, rounded up; 0 for none, UINT64_MAX for an infinite one.
/// A duration that is a whole number of periods gives that number: the quotient's rounding
/// (the two values' and the division's, a few epsilons of Real relative, 1e-9 absolute where
/// that is larger, half a tick at most) does not add a tick. Exact while Real resolves the
/// quotient to better than that: up to 2^21 ticks in float (210 s at 10 kHz), far beyond any
/// configuration in double; above, within float's rounding of the quotient (3 epsilons).
inline uint64_t duration_ticks(Real duration_s, Real period_s) noexcept {
  if (!(duration_s > 0)) return 0;
  const Real quotient = duration_s / period_s;
  const Real rounding = std::min(
      Real(0.5), std::max(Real(1e-9), 4 * std::numeric_limits<Real>::epsilon() * quotient));
  const Real ticks = std::ceil(quotient - rounding);
  // Below 2^32 through a 32-bit conversion: a float's 64-bit one is soft double on the MCU.
  if (ticks < Real(4e9)) return static_cast<uint32_t>(ticks);
  if constexpr (sizeof(Real) == sizeof(double)) {
    return ticks < Real(1e18) ? static_cast<uint64_t>(ticks) : UINT64_MAX;
  } else {
    return UINT64_MAX;  // float's ticks beyond 2^32 (five days at 10 kHz): as good as never
  }
}

}  // namespace imd::firmware
