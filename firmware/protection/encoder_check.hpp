#pragma once
/// Encoder plausibility. Two failures are caught:
///  - a jump: more counts in one tick than 1.5 x the overspeed limit could produce;
///  - silence: no count while the rotor must have turned by more than it can turn unseen,
///    whatever the load does.
///
/// The silence test does not trust the load estimate: a load step makes it wrong for a while,
/// and a check built on it tripped on healthy encoders. It bounds the rotor's motion instead.
/// From the last count on, the speed lies between two bounds that the worst loads drive:
///   J dw_lo/dt = T - L_max - c w_lo,   J dw_hi/dt = T + L_max - c w_hi,
/// with T the electromagnetic torque the drive applies, c the friction and L_max the largest
/// load the check allows for (either sign). They start from the speed estimate at the count,
/// widened by its quantization error and by the lag the largest load step leaves in the encoder
/// observer: a load anywhere within +-L_max can step by 2 L_max, from one end to the other
/// (2 L_max / (J w_obs)). The travel since the count lies between their integrals. A
/// healthy encoder counts once the rotor has crossed `missing_counts` count edges (one for the
/// unknown place within the count at the start, one to spare): if the lower travel bound
/// exceeds that, or the upper one falls below minus that, with no count seen, the encoder has
/// failed.
///
/// So no load within +-L_max trips the check; a failed encoder is found once the rotor must
/// have moved: at speed within a tick or two, at low speed once the drive's torque exceeds
/// L_max (a speed loop on a frozen encoder drives it to its limit). Tick context, no heap.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "control/real.hpp"

namespace imd::firmware {

/// The largest plausible count step: 1.5 x the overspeed limit over one period, plus 2 counts
/// for the latching instant (no limit for an infinite overspeed).
inline int32_t max_jump(Real overspeed_rad_s, Real period_s, Real counts_per_rev) noexcept {
  const Real counts =
      Real(1.5) * overspeed_rad_s * period_s * counts_per_rev / (2 * std::numbers::pi_v<Real>);
  return counts < Real(1e9) ? static_cast<int32_t>(std::ceil(counts)) + 2 : INT32_MAX;
}

template <typename T>
class EncoderCheck {
 public:
  struct Config {
    Real counts_per_rev = 8192.0;
    Real period_s = Real(1e-4);
    Real J_kgm2 = Real(0.01);
    Real friction_Nms = 0.0;
    Real missing_counts = 2.0;
    Real overspeed_rad_s = 400.0;
    /// The speed estimate's error from quantization (control/encoder_quantization_bounds).
    Real speed_error_rad_s = 0.0;
    Real observer_bandwidth_rad_s = 400.0;  ///< the encoder observer's
  };

  explicit EncoderCheck(const Config& c) noexcept
      : period_s_(T(c.period_s)),
        period_per_J_(T(c.period_s / c.J_kgm2)),
        friction_(T(c.friction_Nms)),
        missing_rad_(T(c.missing_counts * 2 * std::numbers::pi_v<Real> / c.counts_per_rev)),
        speed_error_rad_s_(T(c.speed_error_rad_s)),
        // The lag after a load step of 2 L_max, per newton metre of L_max (doubling is exact).
        step_lag_per_Nm_(T(2 / (c.J_kgm2 * c.observer_bandwidth_rad_s))),
        max_jump_counts_(max_jump(c.overspeed_rad_s, c.period_s, c.counts_per_rev)) {
    reset();
  }

  /// Forget the history (after the encoder was (re)started or a fault was cleared).
  void reset() noexcept {
    anchored_ = false;
    omega_lo_ = omega_hi_ = travel_lo_ = travel_hi_ = T(0);
  }

  /// One tick: the counts seen over the last period, the speed estimate now, the
  /// electromagnetic torque over the coming period and the largest load to allow for. With
  /// the PWM off (`driving` false) nothing bounds the load (a braked or held rotor), so only
  /// jumps are judged and the bounds restart when the drive does. True if the encoder failed.
  bool failed(int32_t delta_counts, T omega_est_rad_s, T torque_Nm, T max_load_Nm,
              bool driving = true) noexcept {
    if (delta_counts > max_jump_counts_ || delta_counts < -max_jump_counts_) return true;
    if (!driving) {
      reset();
      return false;
    }
    if (delta_counts != 0 || !anchored_) {  // a count: the rotor is at a count edge now
      const T margin = speed_error_rad_s_ + max_load_Nm * step_lag_per_Nm_;
      omega_lo_ = omega_est_rad_s - margin;
      omega_hi_ = omega_est_rad_s + margin;
      travel_lo_ = travel_hi_ = T(0);
      anchored_ = true;
    } else if (travel_lo_ > missing_rad_ || travel_hi_ < -missing_rad_) {
      return true;
    }
    // Over the coming period; the travel takes the less favourable end of each bound.
    const T lo = omega_lo_ + (torque_Nm - max_load_Nm - friction_ * omega_lo_) * period_per_J_;
    const T hi = omega_hi_ + (torque_Nm + max_load_Nm - friction_ * omega_hi_) * period_per_J_;
    travel_lo_ += std::min(omega_lo_, lo) * period_s_;
    travel_hi_ += std::max(omega_hi_, hi) * period_s_;
    omega_lo_ = lo;
    omega_hi_ = hi;
    return false;
  }

  int32_t max_jump_counts() const noexcept { return max_jump_counts_; }

  /// Takes over the state of the object this one replaces (the same motor but for its
  /// rotor resistance): the tick changes coefficients and keeps state (docs/robustness.md).
  void continue_from(const EncoderCheck& old) noexcept {
    anchored_ = old.anchored_;
    omega_lo_ = old.omega_lo_;
    omega_hi_ = old.omega_hi_;
    travel_lo_ = old.travel_lo_;
    travel_hi_ = old.travel_hi_;
  }

 private:
  T period_s_, period_per_J_, friction_, missing_rad_, speed_error_rad_s_, step_lag_per_Nm_;
  int32_t max_jump_counts_;
  bool anchored_ = false;
  T omega_lo_ = T(0), omega_hi_ = T(0), travel_lo_ = T(0), travel_hi_ = T(0);
};

}  // namespace imd::firmware
