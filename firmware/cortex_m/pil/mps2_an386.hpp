#pragma once
/// The Arm MPS2 board with the AN386 image (Cortex-M4F), as QEMU's mps2-an386 models it.
#include <cstdint>

namespace imd::firmware::mps2 {

inline constexpr uint32_t kCoreClock_Hz = 25'000'000;  ///< SYSCLK: the core and SysTick
inline constexpr uintptr_t kUart0 = 0x40004000;        ///< CMSDK APB UART 0 (QEMU: -serial)
inline constexpr uint32_t kUartBaud_Hz = 115'200;

}  // namespace imd::firmware::mps2
