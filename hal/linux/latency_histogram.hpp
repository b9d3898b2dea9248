#pragma once
/// A histogram of durations in 1 us bins, as cyclictest keeps them, so the two can be compared
/// bin for bin. Recording is O(1) with no allocation (the bins are allocated at construction),
/// safe in the real-time loop; it is read after the loop has stopped.
#include <algorithm>
#include <cstdint>
#include <vector>

namespace imd::hal {

class LatencyHistogram {
 public:
  /// Bins 0..range_us-1 us; longer durations go to the overflow count (their maximum is kept).
  explicit LatencyHistogram(uint32_t range_us = 10000) : bins_(range_us, 0) {}

  void record(int64_t duration_ns) noexcept {
    const uint64_t ns = duration_ns > 0 ? uint64_t(duration_ns) : 0;  // clock steps are 0
    const uint64_t us = ns / 1000;
    if (us < bins_.size()) {
      ++bins_[us];
    } else {
      ++overflows_;
    }
    ++count_;
    sum_ns_ += ns;
    max_ns_ = std::max(max_ns_, ns);
  }

  uint64_t count() const noexcept { return count_; }
  uint64_t overflows() const noexcept { return overflows_; }
  uint64_t max_ns() const noexcept { return max_ns_; }
  double mean_ns() const noexcept { return count_ > 0 ? double(sum_ns_) / double(count_) : 0.0; }
  /// Samples of at least `threshold_us` (bins from it, and the overflows).
  uint64_t count_at_least_us(uint32_t threshold_us) const noexcept {
    uint64_t n = overflows_;
    for (std::size_t us = threshold_us; us < bins_.size(); ++us) n += bins_[us];
    return n;
  }
  /// The upper edge (us) of the bin holding the q-quantile, q in [0, 1]: "q of the samples
  /// took less than this". The overflow bin reports the maximum. 0 with no samples.
  double quantile_us(double q) const noexcept {
    if (count_ == 0) return 0.0;
    const auto rank = static_cast<uint64_t>(q * double(count_ - 1)) + 1;  // 1-based
    uint64_t seen = 0;
    for (std::size_t us = 0; us < bins_.size(); ++us) {
      seen += bins_[us];
      if (seen >= rank) return double(us + 1);
    }
    return double(max_ns_) / 1000.0;
  }
  const std::vector<uint64_t>& bins() const noexcept { return bins_; }

 private:
  std::vector<uint64_t> bins_;
  uint64_t overflows_ = 0, count_ = 0, sum_ns_ = 0, max_ns_ = 0;
};

}  // namespace imd::hal
