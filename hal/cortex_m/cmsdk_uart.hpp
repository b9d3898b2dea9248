#pragma once
/// Transmit-only console on an Arm CMSDK APB UART (the MPS2 boards' UART0 at 0x40004000, as
/// QEMU's mps2-an386 models it). Polled: for reports outside the tick, never from the tick.
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace imd::hal::cortex_m {

class CmsdkUart {
 public:
  /// Enables the transmitter at baud_Hz on a UART clocked at clock_Hz.
  CmsdkUart(uintptr_t base, uint32_t clock_Hz, uint32_t baud_Hz) noexcept;
  void write(std::string_view text) noexcept;

 private:
  uintptr_t base_;
};

}  // namespace imd::hal::cortex_m
