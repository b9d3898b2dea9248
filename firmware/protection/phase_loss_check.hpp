#pragma once
/// Phase loss: the current each phase should carry against the one it does. Each tick the exact
/// model predicts the stator current from the last tick's measured current, the flux estimate
/// and the input that acted (firmware/stages/estimate.hpp). Over a window the check sums, per
/// phase, how much less current the phase carried than predicted: sum(|i_pred| - |i|).
///   * On a healthy motor the measurement noise cancels in that sum (the prediction and the
///     measurement carry alike noise), and the model's systematic error is left: at most the
///     inverter's voltage error over the leakage inductance, du period / sigma per tick.
///   * An open phase carries nothing while the law drives voltage into it to get the current it
///     wants there: the sum grows each tick by the current the law asks of the phase, up to
///     the whole voltage's worth, v_max period / sigma.
/// So it needs no revolution of the flux: it works at standstill, at any speed and with the
/// pulsating flux an open phase leaves. A phase the law wants no current from is harmless
/// while open, and not seen until the law wants current there. Rules: docs/safety.md. Tick
/// context.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "control/real.hpp"

namespace imd::firmware {

template <typename T>
class PhaseLossCheck {
 public:
  struct Config {
    uint32_t window_ticks = 1;
    /// The healthy model's largest mean shortfall per tick, per volt of DC bus (the inverter's
    /// voltage error over the leakage inductance), and the noise of the window's mean.
    Real missing_A_per_bus_V = 0.0;
    Real noise_floor_A = 0.0;
    /// A phase that carries less than this share of its predicted current carries none: an
    /// open phase carries only the measurement noise, a healthy one all of it.
    Real carried_share = 0.5;
    /// And the most an open phase's mean |i| over the window reads: the measurement noise
    /// alone. A phase that carries more is connected: a model that mispredicts it (a rotor
    /// resistance far from the record's, at speed) is not a lost phase. 0: no such bound.
    Real open_mean_A = 0.0;
  };

  explicit PhaseLossCheck(const Config& c) noexcept
      : window_ticks_(std::max<uint32_t>(c.window_ticks, 1)),
        missing_A_per_bus_V_(T(c.missing_A_per_bus_V)),
        noise_floor_A_(T(c.noise_floor_A)),
        carried_share_(T(c.carried_share)),
        open_mean_A_(c.open_mean_A > 0 ? T(c.open_mean_A) : std::numeric_limits<T>::infinity()) {}

  uint32_t window_ticks() const noexcept { return window_ticks_; }
  void reset() noexcept {
    std::fill(std::begin(predicted_A_), std::end(predicted_A_), T(0));
    std::fill(std::begin(measured_A_), std::end(measured_A_), T(0));
    ticks_ = 0;
  }
  /// The inverter does not drive the motor: start afresh, and skip the first tick after, whose
  /// prediction took the open terminals of a PWM-off period for a zero voltage.
  void idle() noexcept {
    reset();
    skip_ = true;
  }

  /// Takes over the sums of the check this one replaces (the same motor but for its rotor
  /// resistance: a window a little longer or shorter).
  void continue_from(const PhaseLossCheck& old) noexcept {
    std::copy(std::begin(old.predicted_A_), std::end(old.predicted_A_), predicted_A_);
    std::copy(std::begin(old.measured_A_), std::end(old.measured_A_), measured_A_);
    ticks_ = old.ticks_;
    skip_ = old.skip_;
  }

  /// Predicted and measured phase currents, the DC bus. The lost phase (0..2), or -1.
  int lost_phase(const T (&i_predicted_abc_A)[3], const T (&i_abc_A)[3], T v_bus_V) noexcept {
    if (skip_) {
      skip_ = false;
      return -1;
    }
    for (int k = 0; k < 3; ++k) {
      predicted_A_[k] += std::abs(i_predicted_abc_A[k]);
      measured_A_[k] += std::abs(i_abc_A[k]);
    }
    if (++ticks_ < window_ticks_) return -1;
    int worst = 0;
    for (int k = 1; k < 3; ++k) {
      if (predicted_A_[k] - measured_A_[k] > predicted_A_[worst] - measured_A_[worst]) worst = k;
    }
    const T allowed_A = (missing_A_per_bus_V_ * v_bus_V + noise_floor_A_) * T(ticks_);
    const bool lost = predicted_A_[worst] - measured_A_[worst] > allowed_A &&
                      measured_A_[worst] < carried_share_ * predicted_A_[worst] &&
                      measured_A_[worst] <= open_mean_A_ * T(ticks_);
    reset();
    return lost ? worst : -1;
  }

 private:
  uint32_t window_ticks_;
  T missing_A_per_bus_V_, noise_floor_A_, carried_share_, open_mean_A_;
  T predicted_A_[3] = {T(0), T(0), T(0)};
  T measured_A_[3] = {T(0), T(0), T(0)};
  uint32_t ticks_ = 0;
  bool skip_ = true;
};

}  // namespace imd::firmware
