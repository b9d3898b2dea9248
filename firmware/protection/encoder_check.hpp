#pragma once
/// Encoder plausibility. Two failures are caught:
///  - a jump: more counts in one tick than 1.5 x the overspeed limit could produce;
///  - silence: no count while the motion model says the rotor has turned by more than it can
///    have turned unseen. The model starts from the estimated speed and load at the last count
///    and integrates the electromagnetic torque the drive applies, so a rotor that is braked to
///    a stop, or held at standstill, predicts no motion. Its start is only as good as those
///    estimates: the encoder's quantization alone leaves them off by up to dw and dL (the
///    observer's bounds, control/encoder_observer.hpp), which move the model by dw t +
///    dL t^2 / (2 J) after t of silence. The allowance is that plus `missing_counts`. It is
///    re-anchored every `window_s`: a drift of the held torque then counts for one window only.
/// Tick context, no heap.
#include <cmath>
#include <cstdint>
#include <numbers>

namespace imd::firmware {

/// The largest plausible count step: 1.5 x the overspeed limit over one period, plus 2 counts
/// for the latching instant (no limit for an infinite overspeed).
inline int32_t max_jump(double overspeed_rad_s, double period_s, double counts_per_rev) noexcept {
  const double counts =
      1.5 * overspeed_rad_s * period_s * counts_per_rev / (2.0 * std::numbers::pi);
  return counts < 1e9 ? static_cast<int32_t>(std::ceil(counts)) + 2 : INT32_MAX;
}

template <typename T>
class EncoderCheck {
 public:
  struct Config {
    double counts_per_rev = 8192.0;
    double period_s = 1e-4;
    double J_kgm2 = 0.01;
    double friction_Nms = 0.0;
    double missing_counts = 2.0;
    double window_s = 0.02;
    double overspeed_rad_s = 400.0;
    /// The estimates' errors from quantization (control/encoder_quantization_bounds).
    double speed_error_rad_s = 0.0;
    double load_error_Nm = 0.0;
  };

  explicit EncoderCheck(const Config& c) noexcept
      : period_s_(T(c.period_s)),
        per_J_(T(1.0 / c.J_kgm2)),
        friction_(T(c.friction_Nms)),
        missing_rad_(T(c.missing_counts * 2.0 * std::numbers::pi / c.counts_per_rev)),
        speed_error_T_(T(c.speed_error_rad_s * c.period_s)),
        load_error_T2_per_2J_(T(c.load_error_Nm * c.period_s * c.period_s / (2.0 * c.J_kgm2))),
        window_ticks_(static_cast<uint32_t>(std::ceil(c.window_s / c.period_s))),
        max_jump_counts_(
            static_cast<int32_t>(std::ceil(1.5 * c.overspeed_rad_s * c.period_s * c.counts_per_rev /
                                           (2.0 * std::numbers::pi))) +
            2) {
    reset();
  }

  /// Forget the history (after the encoder was (re)started or a fault was cleared).
  void reset() noexcept {
    silent_ticks_ = window_ticks_;
    travel_rad_ = omega_rad_s_ = T(0);
  }

  /// One tick: the counts seen over the last period, and the drive's estimates now.
  /// `torque_Nm` is the electromagnetic torque over the coming period. With the PWM off
  /// (`driving` false) the load is unknown (a braked or held rotor), so only jumps are judged
  /// and the model restarts when the drive does. True if the encoder has failed.
  bool failed(int32_t delta_counts, T omega_est_rad_s, T load_est_Nm, T torque_Nm,
              bool driving = true) noexcept {
    if (delta_counts > max_jump_counts_ || delta_counts < -max_jump_counts_) return true;
    if (!driving) {
      reset();
      return false;
    }
    // The model predicted `travel_rad_` over the silence so far (silent_ticks_ periods).
    if (delta_counts == 0 && std::abs(travel_rad_) > allowance_rad(silent_ticks_)) return true;
    if (delta_counts != 0 || silent_ticks_ >= window_ticks_) {  // anchor to the estimate
      omega_rad_s_ = omega_est_rad_s;
      load_Nm_ = load_est_Nm;
      travel_rad_ = T(0);
      silent_ticks_ = 0;
    }
    ++silent_ticks_;
    travel_rad_ += omega_rad_s_ * period_s_;
    omega_rad_s_ += (torque_Nm - load_Nm_ - friction_ * omega_rad_s_) * per_J_ * period_s_;
    return false;
  }

  int32_t max_jump_counts() const noexcept { return max_jump_counts_; }
  /// The travel the model may show after this many periods of silence without a trip.
  T allowance_rad(uint32_t ticks) const noexcept {
    const T n = T(ticks);
    return missing_rad_ + speed_error_T_ * n + load_error_T2_per_2J_ * n * n;
  }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const EncoderCheck& old) noexcept {
    silent_ticks_ = old.silent_ticks_;
    omega_rad_s_ = old.omega_rad_s_;
    load_Nm_ = old.load_Nm_;
    travel_rad_ = old.travel_rad_;
  }

 private:
  T period_s_, per_J_, friction_, missing_rad_, speed_error_T_, load_error_T2_per_2J_;
  uint32_t window_ticks_;
  int32_t max_jump_counts_;
  uint32_t silent_ticks_ = 0;
  T omega_rad_s_ = T(0), load_Nm_ = T(0), travel_rad_ = T(0);
};

}  // namespace imd::firmware
