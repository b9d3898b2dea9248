#pragma once
/// A law without a solution (the DSMC's or the IOL's decoupling matrix singular at its state):
/// `singular_control` latches once the law has had none for a window of ticks in a row.
///   * Meanwhile its output is safe: the IOL holds the current it commanded, the DSMC applies no
///     input beyond the feedback (2); the current, bus and speed checks keep watching.
///   * A fault that breaks the measurement or the power stage (an open phase, a stuck ADC)
///     makes the law's state inconsistent within a tick, and its own check needs a window to
///     see it. The law waits two of the longest of those windows (a window that began before the
///     fault may hold too little of it; the next holds only the fault), so that the cause is
///     reported, not its consequence.
/// Rules: docs/safety.md. Tick context.
#include <algorithm>
#include <cstdint>

namespace imd::firmware {

class LawFailureCheck {
 public:
  explicit LawFailureCheck(uint32_t window_ticks) noexcept
      : window_ticks_(std::max<uint32_t>(window_ticks, 1)) {}

  /// This tick's law found a solution (`law_ok`) or not; true once it has found none for the
  /// window.
  bool failed(bool law_ok) noexcept {
    failures_ = law_ok ? 0 : std::min(failures_ + 1, window_ticks_);
    return failures_ >= window_ticks_;
  }
  void reset() noexcept { failures_ = 0; }
  void continue_from(const LawFailureCheck& old) noexcept { failures_ = old.failures_; }
  uint32_t window_ticks() const noexcept { return window_ticks_; }

 private:
  uint32_t window_ticks_;
  uint32_t failures_ = 0;  ///< ticks in a row without a solution, up to the window
};

}  // namespace imd::firmware
