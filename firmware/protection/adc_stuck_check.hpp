#pragma once
/// Stuck current ADC: the three phase codes repeat exactly for `stuck_ticks` ticks although the
/// applied stator voltage departed from its value at the first repeat enough to move the
/// current by more than four codes. A voltage departure du held for one period moves the
/// current by du * period / sigma_H (the leakage inductance sets di/dt), so the evidence is the
/// norm of the summed departures over the window; jitter around a constant voltage cancels in
/// that sum, and the window restarts every `stuck_ticks`, so it never accumulates. A motor at
/// rest under a constant voltage (steady magnetizing) gives no evidence and is not judged: a
/// quiet converter may legitimately repeat its codes then. Tick context.
#include <array>
#include <cstdint>

#include "control/frames.hpp"
#include "control/real.hpp"

namespace imd::firmware {

template <typename T>
class AdcStuckCheck {
 public:
  AdcStuckCheck(int stuck_ticks, Real period_s, Real sigma_H, Real A_per_code) noexcept
      : stuck_ticks_(stuck_ticks),
        A_per_V_(T(period_s / sigma_H)),
        evidence_needed_A_(T(4 * A_per_code)) {}

  void reset() noexcept {
    same_ticks_ = 0;
    started_ = false;
    repeated_run_ = 0;
  }

  /// `u_V`: the stator voltage applied over the last period (alpha-beta). True if stuck.
  bool stuck(const std::array<uint16_t, 3>& codes, const control::Vec2<T>& u_V) noexcept {
    // Element by element: std::array's == compares through a call of memcmp.
    const bool repeated = started_ && codes[0] == last_codes_[0] && codes[1] == last_codes_[1] &&
                          codes[2] == last_codes_[2];
    started_ = true;
    last_codes_ = codes;
    repeated_run_ = repeated ? repeated_run_ + (repeated_run_ < stuck_ticks_ ? 1 : 0) : 0;
    if (repeated) {
      ++same_ticks_;
      departure_sum_V_ += u_V - u_first_V_;
      if (same_ticks_ < stuck_ticks_) return false;
      if (departure_sum_V_.norm() * A_per_V_ > evidence_needed_A_) return true;
    }
    same_ticks_ = 0;  // a new window from here
    u_first_V_ = u_V;
    departure_sum_V_ = control::Vec2<T>::Zero();
    return false;
  }

  /// Whether the checks that compare the current with the model should wait: the codes
  /// repeat, and for less than one window. A frozen measurement says nothing of the current,
  /// and this check names a stuck converter within its window if the voltage moved. Codes
  /// that stay frozen longer under a still voltage (no evidence here) may as well be a quiet
  /// converter on an open phase: they are judged again (docs/safety.md, "Phase loss").
  bool deferring() const noexcept { return repeated_run_ > 0 && repeated_run_ < stuck_ticks_; }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const AdcStuckCheck& old) noexcept {
    same_ticks_ = old.same_ticks_;
    started_ = old.started_;
    repeated_run_ = old.repeated_run_;
    last_codes_ = old.last_codes_;
    u_first_V_ = old.u_first_V_;
    departure_sum_V_ = old.departure_sum_V_;
  }

 private:
  int stuck_ticks_;
  T A_per_V_, evidence_needed_A_;
  int same_ticks_ = 0;
  bool started_ = false;
  int repeated_run_ = 0;  ///< ticks the codes have repeated in a row, up to stuck_ticks_
  std::array<uint16_t, 3> last_codes_{};
  control::Vec2<T> u_first_V_ = control::Vec2<T>::Zero();
  control::Vec2<T> departure_sum_V_ = control::Vec2<T>::Zero();
};

}  // namespace imd::firmware
