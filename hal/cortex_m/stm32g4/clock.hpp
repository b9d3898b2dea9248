#pragma once
/// System clock of the STM32G431: 170 MHz from an 8 MHz crystal (HSE) through the main PLL,
/// in range 1 boost mode with 4 flash wait states; AHB, APB1 and APB2 undivided (170 MHz), so
/// TIM1 and TIM2 count at 170 MHz, the FDCAN kernel clock is PCLK1 (170 MHz) and the ADCs run
/// from HCLK/4 (42.5 MHz, set in adc_injected.cpp). Also enables the clocks of the peripherals
/// the board uses and the DWT cycle counter. Start-up only, before any driver.
#include <cstdint>

namespace imd::hal::cortex_m::stm32g4 {

inline constexpr uint32_t kHseClock_Hz = 8'000'000;
inline constexpr uint32_t kSystemClock_Hz = 170'000'000;

enum class ClockStatus : uint8_t {
  ok,
  hse_failed,  ///< the crystal did not start: still on HSI16 (16 MHz)
  pll_failed,  ///< the PLL did not lock: still on HSE
};

/// Switches the system clock to 170 MHz (RM0440 §7.2, §6.1.5 boost sequence). On failure the
/// core keeps running on the previous clock and nothing else is configured.
ClockStatus init_system_clock() noexcept;

/// Clocks the GPIO ports A to C, ADC1/2, TIM1, TIM2, FDCAN and SYSCFG (RCC AHB2ENR, APB1ENR1,
/// APB2ENR) and selects PCLK1 as the FDCAN kernel clock.
void enable_peripheral_clocks() noexcept;

/// Starts the DWT cycle counter (DEMCR.TRCENA, DWT_CTRL.CYCCNTENA).
void enable_cycle_counter() noexcept;

/// Debug support (DBGMCU, RM0440 §46, DBGMCU registers): the debugger stays connected while the
/// main loop sleeps (DBG_SLEEP), and a core halted by the debugger stops TIM1, whose outputs are
/// then disabled as if MOE were cleared (DBG_TIM1_STOP): a breakpoint never leaves the last duties
/// switching the power stage.
void configure_debug() noexcept;

}  // namespace imd::hal::cortex_m::stm32g4
