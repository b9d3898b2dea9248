#pragma once
/// Stuck current ADC: the three phase codes repeat exactly while the exact model says the
/// current moved by more than four codes. Each tick the model predicts the current from the one
/// measured at the last tick, the flux estimate, the speed and the voltage that acted
/// (Estimate::i_predicted_alphabeta_A). While the codes repeat, the measured current is the
/// same every tick, so predictions that depart from the ones before say the current should
/// have moved by that much more than it did. A window of `stuck_ticks` repeated ticks is judged
/// by its two halves: the evidence is the norm of the second half's predictions summed against
/// the first half's mean. The window slides by half its length while the codes repeat:
///   * a voltage departure du held for a period moves the prediction by du period / sigma_H,
///     as a stuck converter under a law that chases the frozen reading makes it do;
///   * a voltage that follows the back EMF as the speed changes, at a standstill of the stator
///     frequency where the currents are DC and a quiet converter repeats its codes, does not
///     move the prediction: the model has the back EMF;
///   * a constant model error cancels between the halves, and each judgement takes two
///     halves only, so nothing accumulates;
///   * a phase current within the PWM ripple of zero (|i| < v_bus period / (12 sigma_H), the
///     band of firmware/stages/dead_time_compensation.hpp) changes sign within the period, so
///     the inverter's sign-dependent errors (dead time, device drop) on that phase are partial
///     and unknown: the current can clamp at zero for several periods while the law moves the
///     voltage. That phase's voltage error moves the prediction along its own axis only (a
///     pole voltage e is (2/3) e along the phase's alpha-beta axis), so the evidence along that
///     axis is dropped; with two phases in the band (a current near zero) there is none;
///   * the predictions' tick-to-tick scatter (the law's chatter, the speed estimate's steps at
///     the encoder's edges) enters as noise. Against the window's first prediction alone,
///     that one's scatter would count once per departure; against the mean of half the window
///     the evidence of a held departure is largest for the noise (half and half maximizes
///     sqrt(K (N - K) / N) for K reference ticks of N).
/// A motor at rest under a constant voltage (steady magnetizing) gives no evidence and is not
/// judged: a quiet converter may legitimately repeat its codes then. Tick context.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "control/frames.hpp"
#include "control/real.hpp"

namespace imd::firmware {

template <typename T>
class AdcStuckCheck {
 public:
  /// `A_per_code`: the converter's current step; `sigma_H`: the motor's stator transient
  /// inductance; `period_s`: the PWM period.
  AdcStuckCheck(int stuck_ticks, Real A_per_code, Real sigma_H, Real period_s) noexcept
      : stuck_ticks_(stuck_ticks),
        half_ticks_(std::max(stuck_ticks / 2, 1)),
        evidence_needed_A_(T(4 * A_per_code)),
        band_A_per_V_(T(period_s / (12 * sigma_H))) {}

  void reset() noexcept {
    half_count_ = 0;
    judged_halves_ = false;
    later_sum_A_ = control::Vec2<T>::Zero();
    started_ = false;
    repeated_run_ = 0;
  }

  /// `i_abc_A`: the measured phase currents; `i_predicted_A`: the current the model predicted
  /// for this tick (alpha-beta), valid if `predicted`. True if stuck.
  bool stuck(const std::array<uint16_t, 3>& codes, const T (&i_abc_A)[3], T v_bus_V,
             const control::Vec2<T>& i_predicted_A, bool predicted) noexcept {
    // Element by element: std::array's == compares through a call of memcmp.
    const bool repeated = started_ && codes[0] == last_codes_[0] && codes[1] == last_codes_[1] &&
                          codes[2] == last_codes_[2];
    started_ = true;
    last_codes_ = codes;
    repeated_run_ = repeated ? repeated_run_ + (repeated_run_ < stuck_ticks_ ? 1 : 0) : 0;
    // A window is two halves of stuck_ticks / 2 repeated ticks with a prediction, judged at
    // the end of each half against the one before: it slides by half its length, so that a
    // departure that starts anywhere is judged within a half. Its first tick is the first whose
    // prediction rests on the repeated reading (the one before rests on the codes that changed,
    // and would count their step as evidence).
    if (!repeated || !predicted) {
      half_count_ = 0;
      judged_halves_ = false;
      later_sum_A_ = control::Vec2<T>::Zero();
      return false;
    }
    // Summed as departures from the run's first prediction: small numbers, so that the two
    // halves' difference keeps its precision in float over a long window too.
    if (half_count_ == 0 && !judged_halves_) origin_A_ = i_predicted_A;
    later_sum_A_ += i_predicted_A - origin_A_;
    if (++half_count_ < half_ticks_) return false;
    half_count_ = 0;
    control::Vec2<T> evidence_A = later_sum_A_ - reference_sum_A_;
    const bool judged = judged_halves_;
    judged_halves_ = true;
    reference_sum_A_ = later_sum_A_;
    later_sum_A_ = control::Vec2<T>::Zero();
    if (!judged) return false;
    // The phases' alpha-beta axes; the reading is the same all window, so is its band.
    constexpr T kHalf = T(0.5), kRoot3Half = T(0.8660254037844386);
    const control::Vec2<T> axes[3] = {{T(1), T(0)}, {-kHalf, kRoot3Half}, {-kHalf, -kRoot3Half}};
    const T band_A = band_A_per_V_ * v_bus_V;
    int in_band = 0;
    for (int phase = 0; phase < 3; ++phase) {
      if (std::abs(i_abc_A[phase]) < band_A) {
        ++in_band;
        evidence_A -= evidence_A.dot(axes[phase]) * axes[phase];
      }
    }
    return in_band < 2 && evidence_A.norm() > evidence_needed_A_;
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
    half_count_ = old.half_count_;
    judged_halves_ = old.judged_halves_;
    started_ = old.started_;
    repeated_run_ = old.repeated_run_;
    last_codes_ = old.last_codes_;
    origin_A_ = old.origin_A_;
    reference_sum_A_ = old.reference_sum_A_;
    later_sum_A_ = old.later_sum_A_;
  }

 private:
  int stuck_ticks_, half_ticks_;
  T evidence_needed_A_;
  T band_A_per_V_;              ///< the zero-crossing band per volt of bus
  int half_count_ = 0;          ///< ticks into the current half
  bool judged_halves_ = false;  ///< a complete half precedes the current one
  bool started_ = false;
  int repeated_run_ = 0;  ///< ticks the codes have repeated in a row, up to stuck_ticks_
  std::array<uint16_t, 3> last_codes_{};
  control::Vec2<T> origin_A_ = control::Vec2<T>::Zero();         ///< the run's first prediction
  control::Vec2<T> reference_sum_A_ = control::Vec2<T>::Zero();  ///< the last complete half's
  control::Vec2<T> later_sum_A_ = control::Vec2<T>::Zero();      ///< the current half's
};

}  // namespace imd::firmware
