#pragma once
/// The ARMv7E-M core's system registers this HAL uses (Cortex-M4F): the System Control Block,
/// SysTick, and the FPU's access control. Addresses are the architecture's (ARMv7-M ARM, B3.2),
/// the same on every Cortex-M4 chip.
#include <cstdint>

namespace imd::hal::cortex_m {

inline volatile uint32_t& reg32(uintptr_t address) noexcept {
  return *reinterpret_cast<volatile uint32_t*>(address);
}

// System Control Block.
inline constexpr uintptr_t kScbIcsr = 0xE000ED04;   ///< interrupt control and state
inline constexpr uintptr_t kScbVtor = 0xE000ED08;   ///< vector table offset
inline constexpr uintptr_t kScbShpr3 = 0xE000ED20;  ///< priorities of PendSV [23:16], SysTick [31:24]
inline constexpr uintptr_t kScbCpacr = 0xE000ED88;  ///< coprocessor access (CP10, CP11: the FPU)
inline constexpr uintptr_t kFpuFpccr = 0xE000EF34;  ///< FP context control (lazy stacking)
inline constexpr uint32_t kIcsrPendSvSet = 1u << 28;
inline constexpr uint32_t kIcsrPendSvClr = 1u << 27;

// SysTick.
inline constexpr uintptr_t kSysTickCsr = 0xE000E010;  ///< control and status
inline constexpr uintptr_t kSysTickRvr = 0xE000E014;  ///< reload value (24 bits)
inline constexpr uintptr_t kSysTickCvr = 0xE000E018;  ///< current value, counts down
inline constexpr uint32_t kSysTickEnable = 1u << 0;
inline constexpr uint32_t kSysTickInterrupt = 1u << 1;
inline constexpr uint32_t kSysTickCoreClock = 1u << 2;  ///< count the processor clock
inline constexpr uint32_t kSysTickMaxReload = 0x00FFFFFF;

/// Waits for an interrupt (the core sleeps until one is pending).
inline void wait_for_interrupt() noexcept { asm volatile("wfi" ::: "memory"); }
inline void data_sync_barrier() noexcept { asm volatile("dsb" ::: "memory"); }
inline void instruction_sync_barrier() noexcept { asm volatile("isb" ::: "memory"); }
inline void disable_interrupts() noexcept { asm volatile("cpsid i" ::: "memory"); }
inline void enable_interrupts() noexcept { asm volatile("cpsie i" ::: "memory"); }

}  // namespace imd::hal::cortex_m
