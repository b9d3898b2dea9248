#include "hal/cortex_m/cmsdk_uart.hpp"

#include "hal/cortex_m/armv7m.hpp"

namespace imd::hal::cortex_m {
namespace {

// Registers (Cortex-M System Design Kit TRM, DDI 0479, 4.2).
constexpr uintptr_t kData = 0x00;
constexpr uintptr_t kState = 0x04;
constexpr uintptr_t kCtrl = 0x08;
constexpr uintptr_t kBaudDiv = 0x10;
constexpr uint32_t kStateTxFull = 1u << 0;
constexpr uint32_t kCtrlTxEnable = 1u << 0;

}  // namespace

CmsdkUart::CmsdkUart(uintptr_t base, uint32_t clock_Hz, uint32_t baud_Hz) noexcept : base_(base) {
  const uint32_t divider = clock_Hz / baud_Hz;
  reg32(base_ + kBaudDiv) = divider < 16 ? 16 : divider;  // the UART needs at least 16
  reg32(base_ + kCtrl) = kCtrlTxEnable;
}

void CmsdkUart::write(std::string_view text) noexcept {
  for (const char c : text) {
    if (c == '\n') {
      while ((reg32(base_ + kState) & kStateTxFull) != 0) {
      }
      reg32(base_ + kData) = '\r';
    }
    while ((reg32(base_ + kState) & kStateTxFull) != 0) {
    }
    reg32(base_ + kData) = static_cast<uint8_t>(c);
  }
}

}  // namespace imd::hal::cortex_m
