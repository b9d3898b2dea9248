#pragma once
/// Stuck current ADC: the three phase codes repeat exactly for `stuck_ticks` ticks although the
/// applied stator voltage changed enough to move the current by more than four codes. Over one
/// period a voltage change du changes the current by du * period / sigma_H (the leakage
/// inductance sets di/dt), so a converter that repeats itself against that evidence is stuck.
/// A motor at rest under a constant voltage (steady magnetizing) gives no evidence and is not
/// judged: a quiet converter may legitimately repeat its codes then. Tick context.
#include <array>
#include <cstdint>

#include "control/frames.hpp"

namespace imd::firmware {

template <typename T>
class AdcStuckCheck {
 public:
  AdcStuckCheck(int stuck_ticks, double period_s, double sigma_H, double A_per_code) noexcept
      : stuck_ticks_(stuck_ticks),
        A_per_V_(T(period_s / sigma_H)),
        evidence_needed_A_(T(4.0 * A_per_code)) {}

  void reset() noexcept {
    same_ticks_ = 0;
    evidence_A_ = T(0);
    started_ = false;
  }

  /// `u_V`: the stator voltage applied over the last period (alpha-beta). True if stuck.
  bool stuck(const std::array<uint16_t, 3>& codes, const control::Vec2<T>& u_V) noexcept {
    if (started_ && codes == last_codes_) {
      ++same_ticks_;
      evidence_A_ += (u_V - last_u_V_).norm() * A_per_V_;
    } else {
      same_ticks_ = 0;
      evidence_A_ = T(0);
    }
    started_ = true;
    last_codes_ = codes;
    last_u_V_ = u_V;
    return same_ticks_ >= stuck_ticks_ && evidence_A_ > evidence_needed_A_;
  }

 private:
  int stuck_ticks_;
  T A_per_V_, evidence_needed_A_;
  int same_ticks_ = 0;
  T evidence_A_ = T(0);
  bool started_ = false;
  std::array<uint16_t, 3> last_codes_{};
  control::Vec2<T> last_u_V_ = control::Vec2<T>::Zero();
};

}  // namespace imd::firmware
