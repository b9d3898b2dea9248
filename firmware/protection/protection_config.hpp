#pragma once
/// Protection thresholds. Every check runs each tick, before the written duties act; the
/// defaults are safe for the paper-000 motor on a 311 V bus and are overridden per board or
/// scenario (docs/safety.md explains each check and its detection latency).
#include <cstdint>
#include <limits>

#include "control/real.hpp"
#include "firmware/protection/stop_category.hpp"

namespace imd::firmware {

/// The stuck-ADC check's window as a time: the evidence a window gathers from a held voltage
/// departure is the departure times half the window over sigma Ls (a tick's prediction moves
/// by du period / sigma Ls, summed over half the window's ticks), i.e. volt-seconds, so a
/// window of a fixed tick count would weaken with a shorter period. 2 ms is 20 ticks at 10 kHz.
inline constexpr Real kAdcStuckWindow_s = Real(2e-3);

/// kAdcStuckWindow_s in ticks of `period_s`, rounded, at least the check's minimum of 2.
constexpr int adc_stuck_ticks_for(Real period_s) noexcept {
  const Real ticks = kAdcStuckWindow_s / period_s + Real(0.5);
  return ticks < 2 ? 2 : (ticks > Real(1e6) ? 1'000'000 : static_cast<int>(ticks));
}

struct ProtectionConfig {
  /// The checks on the sensors themselves: off where the drive does not use them (ideal
  /// sensors in simulation give no encoder counts or ADC codes to judge).
  bool check_encoder = true;
  bool check_adc_stuck = true;
  Real overcurrent_A = 10.0;     ///< instantaneous, per phase (and any ADC code on a rail)
  Real bus_min_V = 20.0;         ///< below: undervoltage while enabled (also a NaN reading)
  Real bus_max_V = 450.0;        ///< above: overvoltage, in every state
  Real overspeed_rad_s = 400.0;  ///< |estimated mechanical speed| above: overspeed
  /// Encoder: count edges the rotor must have crossed, whatever the load, before a silence is a
  /// failure (docs/safety.md): one for the unknown place within the count at the start, one to
  /// spare.
  Real encoder_missing_counts = 2.0;
  /// The largest load the encoder check allows for, as a share of the torque the drive can
  /// produce at its current limit with the flux it has (and within its torque limit). No load
  /// up to it trips the check; above it, a frozen encoder is found once the drive's torque
  /// exceeds it. 0.75 leaves a quarter of the torque for the laws' current margins and the
  /// torque estimate's error (docs/safety.md).
  Real encoder_max_load_share = 0.75;
  /// ADC stuck: ticks with identical phase codes while the motor model says the current moved
  /// by several codes. The default is adc_stuck_ticks_for(1e-4), 10 kHz's.
  int adc_stuck_ticks = 20;
  /// Phase loss (firmware/protection/phase_loss_check.hpp): the board's worst voltage error
  /// (dead time, device drops, bus ripple) as a share of the phase voltage range V_bus/sqrt(3),
  /// and its current ADC's rms noise in codes. The check's threshold and window follow from
  /// them, the motor and the sample period (docs/safety.md).
  Real inverter_voltage_error_share = Real(0.05);
  Real adc_noise_codes = 4.0;
  /// Command watchdog while magnetizing or running on CAN commands; 0 disables it.
  Real command_timeout_s = Real(0.2);
  uint32_t tick_budget_ns = 90'000;  ///< execution-time budget; 0: not checked
  /// How the faults that may choose stop (firmware/protection/stop_category.hpp).
  StopPolicy stop;
  /// DC braking: its current, a share of the current limit (docs/safety.md).
  Real dc_brake_current_share = 1.0;
};

}  // namespace imd::firmware
