#pragma once
/// hal::CurrentAdc on ADC1 and ADC2 of the STM32G4 (RM0440 §21), injected groups started
/// together by TIM1 TRGO2 (OC4REF, just before the carrier peak, tim1_pwm.hpp): 12 bits, both
/// ADCs clocked synchronously from HCLK / 4 (42.5 MHz), so the trigger latency is fixed.
///   ADC1: rank 1 phase a (PA0, ADC12_IN1), rank 2 DC bus (PA2, ADC1_IN3)
///   ADC2: rank 1 phase b (PA6, ADC2_IN3),  rank 2 phase c (PA7, ADC2_IN4)
/// Phases a and b are sampled at the same instant, c and the bus one conversion (0.59 us)
/// later. The end of both sequences (JEOS) raises ADC1_2_IRQn: the tick's sample stage
/// (adc_tick.hpp), which calls latch(); the tick reads the latched codes with sample().
#include <cstdint>

#include "hal/current_adc.hpp"

namespace imd::hal::cortex_m::stm32g4 {

/// The board's analog front end: shunt, amplifier and bus divider.
struct AnalogFrontEnd {
  float vref_V = 3.3f;  ///< VREF+ (= VDDA on a 48-pin package)
  uint32_t bits = 12;
  float shunt_Ohm = 0.0f;          ///< per-phase current shunt
  float amplifier_gain = 0.0f;     ///< shunt volts to ADC-pin volts, biased at vref/2
  float bus_divider_ratio = 0.0f;  ///< ADC-pin volts per DC-bus volt
};

/// Codes to amperes and volts: i = (code - 2^(bits-1)) A_per_code, v = code V_per_code.
constexpr hal::AdcScale adc_scale(const AnalogFrontEnd& f) {
  const float lsb_V = f.vref_V / float(1u << f.bits);
  return {lsb_V / (f.shunt_Ohm * f.amplifier_gain), uint16_t(1u << (f.bits - 1)),
          lsb_V / f.bus_divider_ratio, uint16_t((1u << f.bits) - 1)};
}

struct AdcInjectedConfig {
  uint8_t phase_a_channel = 1;  ///< ADC1 rank 1
  uint8_t bus_channel = 3;      ///< ADC1 rank 2
  uint8_t phase_b_channel = 3;  ///< ADC2 rank 1
  uint8_t phase_c_channel = 4;  ///< ADC2 rank 2
  /// SMPx code of every channel: 010 = 12.5 ADC clocks (294 ns; + 12.5 for the conversion).
  uint8_t sampling_time_code = 2;
  hal::AdcScale scale;
};

class AdcInjected final : public hal::CurrentAdc {
 public:
  /// Powers up, calibrates and enables both ADCs and arms the injected sequences on TIM1
  /// TRGO2. Requires the ADC12 clock and the DWT cycle counter (for the regulator start-up
  /// time). Start-up only; ok() tells whether every step completed.
  explicit AdcInjected(const AdcInjectedConfig& config) noexcept;
  bool ok() const noexcept { return ok_; }

  /// The codes latched by the last sample stage. Tick context.
  hal::AdcSample sample() const noexcept override { return latched_; }
  hal::AdcScale scale() const noexcept override { return config_.scale; }

  // For the sample stage (interrupt context, highest priority).
  /// Which injected sequences have ended: bit 0 ADC1, bit 1 ADC2 (their JEOS flags).
  uint32_t ended_sequences() const noexcept;
  static constexpr uint32_t kBothEnded = 0x3;
  /// Clears both JEOS flags (the interrupt request).
  void acknowledge() noexcept;
  /// Copies the four JDR registers into the sample that sample() returns.
  void latch() noexcept;
  /// JEOSIE on both ADCs (the ADC1_2 interrupt itself is the NVIC's, adc_tick.cpp).
  void set_interrupt(bool enabled) noexcept;

 private:
  AdcInjectedConfig config_;
  hal::AdcSample latched_{};
  bool ok_ = false;
};

}  // namespace imd::hal::cortex_m::stm32g4
