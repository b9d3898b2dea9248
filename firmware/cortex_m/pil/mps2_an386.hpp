#pragma once
/// The Arm MPS2 board with the AN386 image (Cortex-M4F), as QEMU's mps2-an386 models it.
#include <cstdint>

namespace imd::firmware::mps2 {

inline constexpr uint32_t kCoreClock_Hz = 25'000'000;  ///< SYSCLK: the core and SysTick
inline constexpr uintptr_t kUart0 = 0x40004000;        ///< CMSDK APB UART 0 (QEMU: -serial)
inline constexpr uintptr_t kWatchdog = 0x40008000;     ///< CMSDK APB watchdog, its IRQ the NMI
inline constexpr uint32_t kUartBaud_Hz = 115'200;

/// CMSDK APB timer 0, free-running down from 2^32 - 1 at the core clock: it times work between
/// ticks, where the lock-stepped SysTick stands still (the main loop's service).
class FreeRunningTimer {
 public:
  FreeRunningTimer() noexcept {
    reg(kReload) = 0xFFFFFFFFu;
    reg(kValue) = 0xFFFFFFFFu;
    reg(kControl) = 1u;  // enable, no interrupt
  }
  /// Counts of the core clock, increasing (wraps at 2^32).
  uint32_t counts() const noexcept { return 0xFFFFFFFFu - reg(kValue); }

 private:
  static constexpr uintptr_t kBase = 0x40000000;
  static constexpr uintptr_t kControl = 0x00, kValue = 0x04, kReload = 0x08;
  static volatile uint32_t& reg(uintptr_t offset) noexcept {
    return *reinterpret_cast<volatile uint32_t*>(kBase + offset);
  }
};

}  // namespace imd::firmware::mps2
