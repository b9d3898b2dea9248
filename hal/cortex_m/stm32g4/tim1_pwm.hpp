#pragma once
/// hal::Pwm on TIM1 of the STM32G4 (RM0440 §28, advanced-control timer): center-aligned
/// counting (0 -> ARR -> 0, one carrier period = 2 ARR counts), complementary outputs
/// CH1/CH1N..CH3/CH3N with hardware dead time, duties through preloaded CCR1..3.
///
/// Timing of one period (docs/porting.md): the counter peak (CNT = ARR, all low-side switches
/// on for duties < 1) is the sampling instant and the period boundary. OC4REF (PWM mode 2,
/// CCR4 = ARR - lead) rises just before the peak and drives TRGO2, which starts the injected
/// ADC conversions; the update event (UEV) that loads the preloaded CCRs happens at the peak
/// only (repetition counter RCR = 1). Duties written by the tick after the sample at peak k
/// thus act from peak k+1 to peak k+2: one period of latency, which the drive predicts over.
///
/// Safe state: MOE = 0 with OSSI = 1 drives every output to its idle level (OISx = OISxN = 0:
/// both switches of each leg off). disable() and force_outputs_off() clear MOE. The hardware
/// over-current trip is the break input BKIN (PB12, AF6): the power stage's over-current
/// comparator on the shunt amplifiers, active low, its threshold set in hardware above the
/// firmware's trip. BKE = 1 clears MOE within the break filter time (47 ns), without software;
/// tripped() tells the drive, which latches `overcurrent` with detail 3. The dead time and
/// break settings are locked (LOCK level 1).
#include <cstdint>

#include "hal/divide_u64.hpp"
#include "hal/pwm.hpp"

namespace imd::hal::cortex_m::stm32g4 {

struct Tim1PwmConfig {
  uint32_t timer_clock_Hz = 170'000'000;  ///< TIM1 kernel clock (APB2 timer clock)
  uint32_t pwm_frequency_Hz = 10'000;     ///< carrier frequency = control rate
  uint32_t dead_time_ns = 1'000;          ///< from the gate driver and switches; rounded up
  /// OC4REF rises this many counts before the peak, so that the ADC's sampling window is
  /// centred on it (trigger latency plus half the sampling time; tune on a scope).
  uint32_t adc_trigger_lead_counts = 30;
  bool break_input = true;        ///< BKIN clears the outputs (the over-current comparator)
  bool break_active_low = true;   ///< the comparator pulls BKIN low on over-current
};

/// The DTG code of TIMx_BDTR for a dead time (RM0440 §28.6, TIMx_BDTR), tDTS = timer clock (CKD =
/// 00); rounded up to the next representable value, saturated at the largest (1008 tDTS).
constexpr uint32_t dead_time_code(uint32_t dead_time_ns, uint32_t timer_clock_Hz) {
  const uint64_t t =
      divide_u64(uint64_t(dead_time_ns) * timer_clock_Hz + 999'999'999u, 1'000'000'000u);
  if (t <= 127) return uint32_t(t);                               // 0xxxxxxx: t
  if (t <= 2 * 127) return 0x80u | uint32_t((t + 1) / 2 - 64);    // 10xxxxxx: (64+x) 2
  if (t <= 8 * 63) return 0xC0u | uint32_t((t + 7) / 8 - 32);     // 110xxxxx: (32+x) 8
  if (t <= 16 * 63) return 0xE0u | uint32_t((t + 15) / 16 - 32);  // 111xxxxx: (32+x) 16
  return 0xFFu;
}
static_assert(dead_time_code(1'000, 170'000'000) == 0x95);  // (64 + 21) x 2 x 5.88 ns = 1 us
static_assert(dead_time_code(500, 170'000'000) == 85);

class Tim1Pwm final : public hal::Pwm {
 public:
  /// Configures TIM1 with the outputs off (MOE = 0) and the counter stopped. Requires the
  /// TIM1 clock; configure the pins (alternate function) after this, so that they go straight
  /// to the idle level.
  explicit Tim1Pwm(const Tim1PwmConfig& config) noexcept;

  /// Starts the counter and checks on the timer itself that the update event comes at the
  /// peak (the counter counts down right after it), moving it there if it came at the valley.
  /// False if it could not be placed: the drive must not run. Start-up only, interrupts off.
  bool start() noexcept;

  /// Preloads CCR1..3 = duty * ARR (clamped to [0, 1]); they take effect at the next peak.
  /// Tick context.
  void set_duties(const PhaseDuties& duty) noexcept override;
  void enable() noexcept override;   ///< MOE = 1. Tick context.
  void disable() noexcept override;  ///< MOE = 0: all switches off. Tick context.
  bool enabled() const noexcept override;
  bool tripped() const noexcept override;
  void clear_trip() noexcept override;
  float period_s() const noexcept override { return period_s_; }

  /// The carrier's auto-reload value (half a period in counts).
  uint32_t auto_reload() const noexcept { return arr_; }
  /// MOE = 0 without an object: for fault handlers (any context, one register write).
  static void force_outputs_off() noexcept;

 private:
  uint32_t arr_;
  float period_s_;
};

}  // namespace imd::hal::cortex_m::stm32g4
