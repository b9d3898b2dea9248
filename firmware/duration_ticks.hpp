#pragma once
/// Durations in whole control periods (construction only: double arithmetic).
#include <cmath>
#include <cstdint>

namespace imd::firmware {

/// `duration_s` in ticks of `period_s`, rounded up; 0 for none, UINT64_MAX for an infinite one.
inline uint64_t duration_ticks(double duration_s, double period_s) noexcept {
  if (!(duration_s > 0)) return 0;
  const double ticks = std::ceil(duration_s / period_s - 1e-9);
  return ticks < 1e18 ? static_cast<uint64_t>(ticks) : UINT64_MAX;
}

}  // namespace imd::firmware
