#pragma once
/// Running mean and maximum of the tick's execution time.
#include <cstdint>

#include "hal/divide_u64.hpp"

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
  /// The mean in whole nanoseconds: integer arithmetic for the tick (telemetry), with 32-bit
  /// divisions (hal/divide_u64.hpp). Exact below 2^31 ticks (2.5 days at 10 kHz); beyond, both
  /// sums lose the same low bits first, within one part in 2^30.
  uint64_t mean_whole_ns() const noexcept {
    uint64_t n = count, total = total_ns;
    while (n >= (uint64_t(1) << 31)) {
      n >>= 1;
      total >>= 1;
    }
    return n ? hal::divide_u64(total, uint32_t(n)) : 0;
  }
};

}  // namespace imd::firmware
