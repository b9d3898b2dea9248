#pragma once
/// Phase loss: over each revolution of the flux (in the stator frame), the mean |i| of every
/// phase is compared. A healthy motor's phase currents are equal sinusoids over a revolution;
/// with one phase open its current stays at zero while the other two carry the whole current.
/// Revolutions slower than `max_window_ticks` (near standstill) are not judged: a balanced DC
/// current may legitimately be zero in one phase. Tick context.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace imd::firmware {

template <typename T>
class PhaseLossCheck {
 public:
  PhaseLossCheck(double ratio, double min_current_A, uint32_t max_window_ticks) noexcept
      : ratio_(T(ratio)), min_current_A_(T(min_current_A)), max_window_ticks_(max_window_ticks) {}

  void reset() noexcept {
    clear();
    started_ = false;
  }

  /// Phase currents and the flux angle in the stator frame. The lost phase (0..2), or -1.
  int lost_phase(const T (&i_abc_A)[3], T flux_angle_rad) noexcept {
    if (!started_) {
      last_angle_rad_ = flux_angle_rad;
      started_ = true;
    }
    T step = flux_angle_rad - last_angle_rad_;  // wrapped to (-pi, pi]
    const T two_pi = T(2 * std::numbers::pi);
    step -= two_pi * std::round(step / two_pi);
    swept_rad_ += step;
    last_angle_rad_ = flux_angle_rad;
    for (int k = 0; k < 3; ++k) sum_abs_A_[k] += std::abs(i_abc_A[k]);
    ++ticks_;
    if (std::abs(swept_rad_) >= two_pi) {
      int weakest = 0, strongest = 0;
      for (int k = 1; k < 3; ++k) {
        if (sum_abs_A_[k] < sum_abs_A_[weakest]) weakest = k;
        if (sum_abs_A_[k] > sum_abs_A_[strongest]) strongest = k;
      }
      const bool carries = sum_abs_A_[strongest] >= min_current_A_ * T(ticks_);
      const bool lost = carries && sum_abs_A_[weakest] < ratio_ * sum_abs_A_[strongest];
      clear();
      if (lost) return weakest;
    } else if (ticks_ >= max_window_ticks_) {
      clear();
    }
    return -1;
  }

 private:
  void clear() noexcept {
    std::fill(std::begin(sum_abs_A_), std::end(sum_abs_A_), T(0));
    swept_rad_ = T(0);
    ticks_ = 0;
  }

  T ratio_, min_current_A_;
  uint32_t max_window_ticks_;
  bool started_ = false;
  T last_angle_rad_ = T(0), swept_rad_ = T(0);
  T sum_abs_A_[3] = {T(0), T(0), T(0)};
  uint32_t ticks_ = 0;
};

}  // namespace imd::firmware
