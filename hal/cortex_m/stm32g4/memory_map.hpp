#pragma once
/// STM32G431 (Cortex-M4F) memory map and interrupt numbers, as RM0440 gives them; each driver
/// of this folder keeps its own register offsets and bits next to its code. No vendor header is
/// used: the values are written out and cited (section numbers of RM0440; the addresses were
/// cross-checked against ST's stm32g431xx.h).
#include <cstdint>

namespace imd::hal::cortex_m::stm32g4 {

// Memory (RM0440 §2.2.2, memory map; DS12589 §3.4): flash 128 KiB; SRAM1 16 KiB at
// 0x20000000, SRAM2 6 KiB at 0x20004000 and CCM SRAM 10 KiB (at 0x10000000, aliased at
// 0x20005800), so the three make one contiguous 32 KiB block at 0x20000000.
inline constexpr uintptr_t kFlashBase = 0x0800'0000;
inline constexpr uintptr_t kSramBase = 0x2000'0000;

// Peripheral base addresses (RM0440 §2.2.2, Table 4).
inline constexpr uintptr_t kTim2 = 0x4000'0000;             // APB1
inline constexpr uintptr_t kFdcan1 = 0x4000'6400;           // APB1
inline constexpr uintptr_t kFdcanConfig = 0x4000'6500;      // CKDIV, shared by the FDCANs
inline constexpr uintptr_t kIwdg = 0x4000'3000;             // APB1
inline constexpr uintptr_t kPwr = 0x4000'7000;              // APB1
inline constexpr uintptr_t kFdcanMessageRam = 0x4000'A400;  // SRAMCAN, FDCAN1 first
inline constexpr uintptr_t kTim1 = 0x4001'2C00;             // APB2
inline constexpr uintptr_t kRcc = 0x4002'1000;              // AHB1
inline constexpr uintptr_t kFlash = 0x4002'2000;            // AHB1, the flash interface
inline constexpr uintptr_t kGpioA = 0x4800'0000;            // AHB2
inline constexpr uintptr_t kGpioB = 0x4800'0400;
inline constexpr uintptr_t kGpioC = 0x4800'0800;
inline constexpr uintptr_t kAdc1 = 0x5000'0000;  // AHB2
inline constexpr uintptr_t kAdc2 = 0x5000'0100;
inline constexpr uintptr_t kAdc12Common = 0x5000'0300;

// Device interrupt numbers, i.e. positions in the vector table after the 16 core entries
// (RM0440 §14.3, Table 97; vectors.cpp holds the whole table).
inline constexpr uint32_t kIrqAdc1_2 = 18;
inline constexpr uint32_t kIrqFdcan1It0 = 21;
inline constexpr uint32_t kIrqTim1Brk = 24;  // TIM1_BRK_TIM15
inline constexpr uint32_t kIrqCount = 102;   // positions 0..101 (FMAC is the last)

}  // namespace imd::hal::cortex_m::stm32g4
