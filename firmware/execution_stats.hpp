#pragma once
/// Running mean and maximum of the tick's execution time.
#include <cstdint>

#include "hal/u64_to_real.hpp"

namespace imd::firmware {

struct ExecutionStats {
  uint64_t count = 0;
  uint64_t total_ns = 0;
  uint32_t max_ns = 0;
  uint64_t overruns = 0;  ///< ticks over the budget

  void add(uint32_t ns) noexcept {
    ++count;
    total_ns += ns;
    if (ns > max_ns) max_ns = ns;
  }
  double mean_ns() const noexcept { return count ? double(total_ns) / double(count) : 0.0; }
  /// The mean in whole nanoseconds, exact (a 64-bit division: reports, not the MCU's tick).
  uint64_t mean_whole_ns() const noexcept { return count ? total_ns / count : 0; }
  /// The mean in microseconds for the telemetry, in the tick: two conversions and one float
  /// division, a fixed cost (a 64-bit integer division is a library call on the MCU, and a
  /// long division by the tick count grows with it). Each sum within an ulp of its float
  /// (hal/u64_to_real.hpp, no 64-bit conversion either): the mean to 3.6e-7 of itself.
  float mean_us() const noexcept {
    return count ? hal::u64_to_real<float>(total_ns) / hal::u64_to_real<float>(count) * 1e-3f
                 : 0.0f;
  }
};

}  // namespace imd::firmware
