#pragma once
/// Running mean and maximum of the tick's execution time.
#include <cstdint>

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
  /// The mean in whole nanoseconds: integer arithmetic, for the tick (telemetry).
  uint64_t mean_whole_ns() const noexcept { return count ? total_ns / count : 0; }
};

}  // namespace imd::firmware
