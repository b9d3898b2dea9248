#pragma once
/// Dead-time compensation in the modulate stage. During the dead time t_d of each switching
/// edge the phase current's diode sets the pole voltage, so a leg delivering a positive current
/// loses t_d/T v_bus of its average pole voltage and a negative one gains it (hal_sim's
/// inverter model, docs/scenarios.md). The compensation adds the loss back to the duty:
/// d += s(i) t_d/T, with i the phase current predicted for the period the duties act on.
///
/// s(i) is sign(i) scaled down linearly within +-i_band of zero: near zero the PWM ripple makes
/// the current change sign within the period, so the dead time's error is partial there, and a
/// predicted current's sign is not certain. i_band is half the largest peak-to-peak ripple of a
/// phase current of a two-level inverter into the stator transient inductance sigma over one
/// PWM period T, v_bus T / (6 sigma) / 2 (a leg at 50 % duty against the star point). The
/// device drop is not compensated: it is not known to the firmware, and identification cancels
/// it (docs/identification.md). Tick context except construction.
#include <algorithm>

#include "control/real.hpp"
#include "control/svpwm.hpp"
#include "hal/pwm.hpp"

namespace imd::firmware {

template <typename T>
class DeadTimeCompensation {
 public:
  /// `dead_time_s`: what the board programs per edge (0 or `enabled` false: no compensation);
  /// `sigma_H`: the motor's stator transient inductance; `period_s`: the PWM period.
  DeadTimeCompensation(bool enabled, Real dead_time_s, Real period_s, Real sigma_H) noexcept
      : active_(enabled && dead_time_s > 0),
        dead_time_share_(T(dead_time_s / period_s)),
        band_A_per_V_(T(period_s / (12 * sigma_H))) {}

  bool active() const noexcept { return active_; }

  /// The duties with the dead time's loss added back, for the phase currents `i_alphabeta_A`
  /// expected over the period, on a bus of `v_bus_V`.
  void apply(hal::PhaseDuties& duty, const control::Vec2<T>& i_alphabeta_A,
             T v_bus_V) const noexcept {
    if (!active_) return;
    const control::PhaseValues<T> i_abc = control::inverse_clarke(i_alphabeta_A);
    const T band_A = std::max(band_A_per_V_ * v_bus_V, T(1e-6));
    for (int phase = 0; phase < 3; ++phase) {
      const T share = std::clamp(i_abc[phase] / band_A, T(-1), T(1)) * dead_time_share_;
      duty[phase] = std::clamp(duty[phase] + float(share), 0.0f, 1.0f);
    }
  }

 private:
  bool active_;
  T dead_time_share_;  ///< t_d / T
  T band_A_per_V_;     ///< i_band / v_bus
};

}  // namespace imd::firmware
