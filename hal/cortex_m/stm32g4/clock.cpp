#include "hal/cortex_m/stm32g4/clock.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"
#include "hal/cortex_m/stm32g4/nvic_dwt.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// RCC registers (RM0440 §7.4).
constexpr uintptr_t kRccCr = kRcc + 0x00;
constexpr uintptr_t kRccCfgr = kRcc + 0x08;
constexpr uintptr_t kRccPllcfgr = kRcc + 0x0C;
constexpr uintptr_t kRccAhb2enr = kRcc + 0x4C;
constexpr uintptr_t kRccApb1enr1 = kRcc + 0x58;
constexpr uintptr_t kRccApb2enr = kRcc + 0x60;
constexpr uintptr_t kRccCcipr = kRcc + 0x88;
constexpr uint32_t kCrHseon = 1u << 16;
constexpr uint32_t kCrHserdy = 1u << 17;
constexpr uint32_t kCrPllon = 1u << 24;
constexpr uint32_t kCrPllrdy = 1u << 25;
constexpr uint32_t kCfgrSwMask = 0x3u << 0;  // SW: 01 HSI16, 10 HSE, 11 PLL
constexpr uint32_t kCfgrSwHse = 0x2u << 0;
constexpr uint32_t kCfgrSwPll = 0x3u << 0;
constexpr uint32_t kCfgrSwsMask = 0x3u << 2;  // SWS: the clock in use, same coding
constexpr uint32_t kCfgrSwsHse = 0x2u << 2;
constexpr uint32_t kCfgrSwsPll = 0x3u << 2;
constexpr uint32_t kCfgrHpreMask = 0xFu << 4;  // AHB prescaler: 0xxx /1, 1000 /2
constexpr uint32_t kCfgrHpreDiv2 = 0x8u << 4;
constexpr uint32_t kCfgrPpreMask = (0x7u << 8) | (0x7u << 11);  // APB1, APB2: 0xx /1
// PLLCFGR: PLLSRC [1:0] (11 HSE), PLLM [7:4] (divider - 1), PLLN [14:8], PLLREN [24],
// PLLR [26:25] (00: /2). 8 MHz / 2 = 4 MHz (VCO input 2.66..8 MHz), x 85 = 340 MHz (VCO 96..344
// MHz), / 2 = 170 MHz.
constexpr uint32_t kPllSrcHse = 0x3u << 0;
constexpr uint32_t kPllM = 2, kPllN = 85, kPllR = 2;
constexpr uint32_t kPllcfgr =
    kPllSrcHse | ((kPllM - 1) << 4) | (kPllN << 8) | (1u << 24) | (((kPllR / 2) - 1) << 25);
static_assert(kHseClock_Hz / kPllM * kPllN / kPllR == kSystemClock_Hz);
constexpr uint32_t kAhb2GpioA = 1u << 0, kAhb2GpioB = 1u << 1, kAhb2GpioC = 1u << 2;
constexpr uint32_t kAhb2Adc12 = 1u << 13;
constexpr uint32_t kApb1Tim2 = 1u << 0, kApb1Fdcan = 1u << 25, kApb1Pwr = 1u << 28;
constexpr uint32_t kApb2Syscfg = 1u << 0, kApb2Tim1 = 1u << 11;
constexpr uint32_t kCciprFdcanselMask = 0x3u << 24;  // 00 HSE, 01 PLL Q, 10 PCLK1
constexpr uint32_t kCciprFdcanselPclk1 = 0x2u << 24;

// Flash access control register FLASH_ACR (RM0440 §3.7.1; wait states by HCLK in §3.3.3): 4 WS
// up to 170 MHz in range 1 boost mode, with prefetch and the instruction and data caches.
constexpr uintptr_t kFlashAcr = kFlash + 0x00;
constexpr uint32_t kAcrLatencyMask = 0xFu << 0;
constexpr uint32_t kAcrLatency4 = 4u << 0;
constexpr uint32_t kAcrPrften = 1u << 8, kAcrIcen = 1u << 9, kAcrDcen = 1u << 10;

// PWR_CR5.R1MODE (RM0440 §6.4, PWR_CR5 at offset 0x80): 0 selects range 1 boost mode, needed
// above 150 MHz. Range 1 (PWR_CR1.VOS = 01) is the reset value.
constexpr uintptr_t kPwrCr5 = kPwr + 0x80;
constexpr uint32_t kCr5R1mode = 1u << 8;

// DBGMCU (RM0440 §46, DBGMCU registers): CR at 0x04 (DBG_SLEEP bit 0), APB2FZ at 0x10
// (DBG_TIM1_STOP bit 11).
constexpr uintptr_t kDbgmcuCr = 0xE004'2004;
constexpr uintptr_t kDbgmcuApb2fz = 0xE004'2010;
constexpr uint32_t kDbgSleep = 1u << 0;
constexpr uint32_t kDbgTim1Stop = 1u << 11;

constexpr uint32_t kReadyPolls = 200'000;  // several ms at 16 MHz: HSE starts in ~2 ms

/// Reads a register back: the preceding write has reached the peripheral.
void read_back(uintptr_t address) noexcept {
  const uint32_t value = reg32(address);
  asm volatile("" : : "r"(value));
}

bool wait_set(uintptr_t address, uint32_t mask, uint32_t value) noexcept {
  for (uint32_t n = 0; n < kReadyPolls; ++n) {
    if ((reg32(address) & mask) == value) return true;
  }
  return false;
}

void delay_cycles(uint32_t cycles) noexcept {
  for (uint32_t n = 0; n < cycles; ++n) asm volatile("nop");
}

}  // namespace

ClockStatus init_system_clock() noexcept {
  reg32(kRccApb1enr1) |= kApb1Pwr;
  read_back(kRccApb1enr1);  // the write takes effect before PWR is accessed

  reg32(kRccCr) |= kCrHseon;
  if (!wait_set(kRccCr, kCrHserdy, kCrHserdy)) return ClockStatus::hse_failed;
  reg32(kRccCfgr) = (reg32(kRccCfgr) & ~kCfgrSwMask) | kCfgrSwHse;
  wait_set(kRccCfgr, kCfgrSwsMask, kCfgrSwsHse);

  reg32(kRccCr) &= ~kCrPllon;
  wait_set(kRccCr, kCrPllrdy, 0);
  reg32(kRccPllcfgr) = kPllcfgr;
  reg32(kRccCr) |= kCrPllon;
  if (!wait_set(kRccCr, kCrPllrdy, kCrPllrdy)) return ClockStatus::pll_failed;

  // Boost sequence (RM0440 §6.1.5): HCLK / 2 first, boost mode, wait states for the new
  // frequency, switch, then after at least 1 us HCLK / 1.
  reg32(kRccCfgr) = (reg32(kRccCfgr) & ~(kCfgrHpreMask | kCfgrPpreMask)) | kCfgrHpreDiv2;
  reg32(kPwrCr5) &= ~kCr5R1mode;
  reg32(kFlashAcr) =
      (reg32(kFlashAcr) & ~kAcrLatencyMask) | kAcrLatency4 | kAcrPrften | kAcrIcen | kAcrDcen;
  wait_set(kFlashAcr, kAcrLatencyMask, kAcrLatency4);
  reg32(kRccCfgr) = (reg32(kRccCfgr) & ~kCfgrSwMask) | kCfgrSwPll;
  wait_set(kRccCfgr, kCfgrSwsMask, kCfgrSwsPll);
  delay_cycles(200);  // > 1 us at 85 MHz HCLK
  reg32(kRccCfgr) &= ~kCfgrHpreMask;
  return ClockStatus::ok;
}

void enable_peripheral_clocks() noexcept {
  reg32(kRccAhb2enr) |= kAhb2GpioA | kAhb2GpioB | kAhb2GpioC | kAhb2Adc12;
  reg32(kRccApb1enr1) |= kApb1Tim2 | kApb1Fdcan | kApb1Pwr;
  reg32(kRccApb2enr) |= kApb2Syscfg | kApb2Tim1;
  reg32(kRccCcipr) = (reg32(kRccCcipr) & ~kCciprFdcanselMask) | kCciprFdcanselPclk1;
  read_back(kRccApb2enr);  // the enables take effect before the first peripheral access
}

void configure_debug() noexcept {
  reg32(kDbgmcuCr) |= kDbgSleep;
  reg32(kDbgmcuApb2fz) |= kDbgTim1Stop;
}

void enable_cycle_counter() noexcept {
  reg32(kDemcr) |= kDemcrTrcena;
  reg32(kDwtCyccnt) = 0;
  reg32(kDwtCtrl) |= kDwtCtrlCyccntena;
}

}  // namespace imd::hal::cortex_m::stm32g4
