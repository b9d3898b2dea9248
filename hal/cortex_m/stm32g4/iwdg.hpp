#pragma once
/// The independent watchdog of the STM32G4 (RM0440 §42, IWDG) and the reset cause (RCC_CSR,
/// RM0440 §7.4.29). The IWDG runs from the LSI (32 kHz), which its start turns on by hardware,
/// and nothing but a reset stops it once started. The drive feeds it at the end of every
/// tick's control stage (firmware/drive.cpp): a tick that stalls or never comes lets it expire,
/// and the reset starts the board with TIM1 stopped, its pins floating until main configures
/// them (the gate drivers' pull-downs keep the switches off, docs/porting.md).
#include <cstdint>

#include "hal/watchdog.hpp"

namespace imd::hal::cortex_m::stm32g4 {

class Iwdg final : public hal::Watchdog {
 public:
  /// Starts it with a period of `timeout_us` (rounded down to the LSI's 125 us at prescaler
  /// 4; 125 us .. 512 ms; the LSI is good to about 8 %). Returns once the prescaler and reload
  /// are taken (a few LSI cycles). Until then feed() does nothing.
  void start(uint32_t timeout_us) noexcept;
  void feed() noexcept override;
};

/// Why the chip last reset, from RCC_CSR's flags, which it then clears (RMVF) so that the next
/// reset is told apart.
hal::ResetCause take_reset_cause() noexcept;

}  // namespace imd::hal::cortex_m::stm32g4
