#pragma once
/// The two ARMv7-M core blocks the board port needs besides hal/cortex_m/armv7m.hpp: the NVIC
/// (device interrupts: enable and priority) and the DWT cycle counter (the execution clock).
/// Addresses are the architecture's (ARMv7-M ARM B3.4 NVIC, C1.8 DWT, C1.6.5 DEMCR). The
/// STM32G4 implements 4 priority bits (the upper nibble of each priority byte).
#include <cstdint>

#include "hal/cortex_m/armv7m.hpp"

namespace imd::hal::cortex_m::stm32g4 {

inline constexpr uintptr_t kNvicIser = 0xE000'E100;  ///< set-enable, one bit per interrupt
inline constexpr uintptr_t kNvicIcer = 0xE000'E180;  ///< clear-enable
inline constexpr uintptr_t kNvicIcpr = 0xE000'E280;  ///< clear-pending
inline constexpr uintptr_t kNvicIpr = 0xE000'E400;   ///< one priority byte per interrupt
inline constexpr uintptr_t kDemcr = 0xE000'EDFC;     ///< debug exception and monitor control
inline constexpr uint32_t kDemcrTrcena = 1u << 24;   ///< enables the DWT (and ITM)
inline constexpr uintptr_t kDwtCtrl = 0xE000'1000;
inline constexpr uint32_t kDwtCtrlCyccntena = 1u << 0;
inline constexpr uintptr_t kDwtCyccnt = 0xE000'1004;  ///< 32-bit core cycle counter

inline constexpr uint8_t kPriorityHighest = 0x00;
inline constexpr uint8_t kPriorityLowest = 0xF0;  // 4 implemented bits

inline void nvic_set_priority(uint32_t irq, uint8_t priority) noexcept {
  *reinterpret_cast<volatile uint8_t*>(kNvicIpr + irq) = priority;
}
inline void nvic_enable(uint32_t irq) noexcept {
  reg32(kNvicIcpr + 4 * (irq / 32)) = 1u << (irq % 32);  // drop a stale pending request
  reg32(kNvicIser + 4 * (irq / 32)) = 1u << (irq % 32);
}
inline void nvic_disable(uint32_t irq) noexcept {
  reg32(kNvicIcer + 4 * (irq / 32)) = 1u << (irq % 32);
  data_sync_barrier();
  instruction_sync_barrier();
}

/// The core cycle counter (170 MHz: wraps every 25.3 s).
inline uint32_t cycle_count() noexcept {
  return reg32(kDwtCyccnt);
}

}  // namespace imd::hal::cortex_m::stm32g4
