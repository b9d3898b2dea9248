#pragma once
/// hal::Encoder on TIM2 of the STM32G4 (RM0440 §29, general-purpose timer; TIM2 is 32-bit):
/// encoder mode 3 (SMS = 011, counting both edges of TI1 and TI2: four counts per line), with
/// the 32-bit counter free-running over 0..2^32-1, so it wraps as hal::Encoder expects.
/// Pins (board): TI1 = PA15 (TIM2_CH1, AF1), TI2 = PB3 (TIM2_CH2, AF1).
#include <cstdint>

#include "hal/encoder.hpp"

namespace imd::hal::cortex_m::stm32g4 {

struct TimEncoderConfig {
  uint32_t counts_per_rev = 8192;  ///< 4 x lines
  /// ICxF input filter code (RM0440 §29.4, TIMx_CCMR1): 0011 = 8 samples at the timer clock
  /// (47 ns); raise it for a noisy cable.
  uint8_t input_filter = 3;
  bool reverse = false;  ///< counts down for forward rotation: inverts TI1 (CC1P)
};

class TimEncoder final : public hal::Encoder {
 public:
  /// Configures TIM2 and starts counting from 0. Requires the TIM2 clock.
  explicit TimEncoder(const TimEncoderConfig& config) noexcept;

  /// The counter as latched by the sample stage. Tick context.
  uint32_t count() const noexcept override { return latched_; }
  uint32_t counts_per_rev() const noexcept override { return config_.counts_per_rev; }

  /// Reads the counter for this period (the sample stage, interrupt context).
  void latch() noexcept;

 private:
  TimEncoderConfig config_;
  uint32_t latched_ = 0;
};

}  // namespace imd::hal::cortex_m::stm32g4
