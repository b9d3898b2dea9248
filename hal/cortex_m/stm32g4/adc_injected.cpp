#include "hal/cortex_m/stm32g4/adc_injected.hpp"

#include <initializer_list>

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/clock.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"
#include "hal/cortex_m/stm32g4/nvic_dwt.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// ADC registers (RM0440 §21.7), offsets from ADC1 or ADC2.
constexpr uintptr_t kIsr = 0x00;
constexpr uintptr_t kIer = 0x04;
constexpr uintptr_t kCr = 0x08;
constexpr uintptr_t kCfgr = 0x0C;
constexpr uintptr_t kSmpr1 = 0x14;  // channels 0..9, 3 bits each; SMPR2 (0x18) 10..18
constexpr uintptr_t kJsqr = 0x4C;
constexpr uintptr_t kJdr1 = 0x80;  // JDR2 0x84
constexpr uint32_t kIsrAdrdy = 1u << 0;
constexpr uint32_t kIsrJeos = 1u << 6;  // also the JEOSIE bit of IER
constexpr uint32_t kCrAden = 1u << 0;
constexpr uint32_t kCrJadstart = 1u << 3;
constexpr uint32_t kCrAdvregen = 1u << 28;
constexpr uint32_t kCrAdcal = 1u << 31;    // ADCALDIF (bit 30) = 0: single-ended calibration
constexpr uint32_t kCfgrJqdis = 1u << 31;  // injected queue off; RES = 00 (12 bits), right aligned
// JSQR: JL [1:0] (length - 1), JEXTSEL [6:2], JEXTEN [8:7], JSQ1 [13:9], JSQ2 [19:15].
// JEXTSEL 01000 = TIM1_TRGO2 for ADC1/ADC2 (RM0440 §21.4, table "ADC1/2 - External triggers
// for injected channels": jext8; ST's LL_ADC_INJ_TRIG_EXT_TIM1_TRGO2 is JEXTSEL_3 too),
// JEXTEN 01 = rising edge.
constexpr uint32_t kJsqrLength2 = 1u << 0;
constexpr uint32_t kJextselTim1Trgo2 = 8u << 2;
constexpr uint32_t kJextenRising = 1u << 7;
constexpr uint32_t jsqr(uint32_t rank1, uint32_t rank2) {
  return kJsqrLength2 | kJextselTim1Trgo2 | kJextenRising | (rank1 << 9) | (rank2 << 15);
}
// ADC12 common control register CCR (RM0440 §21.8): CKMODE [17:16] = 11, HCLK / 4 (42.5 MHz,
// below the 60 MHz maximum; synchronous, so the trigger-to-sample delay has no jitter).
constexpr uintptr_t kCommonCcr = kAdc12Common + 0x08;
constexpr uint32_t kCkmodeMask = 0x3u << 16;
constexpr uint32_t kCkmodeHclkDiv4 = 0x3u << 16;

constexpr uint32_t kRegulatorStartup_cycles = 25 * (kSystemClock_Hz / 1'000'000);  // 20 us + margin
constexpr uint32_t kPolls = 100'000;

bool wait_clear(uintptr_t address, uint32_t mask) noexcept {
  for (uint32_t n = 0; n < kPolls; ++n) {
    if ((reg32(address) & mask) == 0) return true;
  }
  return false;
}

void set_sampling_time(uintptr_t adc, uint32_t channel, uint32_t code) noexcept {
  const uintptr_t smpr = adc + kSmpr1 + (channel >= 10 ? 4u : 0u);
  const uint32_t shift = 3u * (channel % 10);
  reg32(smpr) = (reg32(smpr) & ~(0x7u << shift)) | ((code & 0x7u) << shift);
}

/// Deep power-down off, regulator on, single-ended calibration, enable (RM0440 §21.4.6 to
/// §21.4.9). ADEN is written until ADRDY is set: a write just after calibration may be lost
/// (ST's motor-control SDK does the same).
bool power_up(uintptr_t adc) noexcept {
  reg32(adc + kCr) = 0;  // DEEPPWD = 0
  reg32(adc + kCr) = kCrAdvregen;
  const uint32_t start = cycle_count();
  while (cycle_count() - start < kRegulatorStartup_cycles) {
  }
  reg32(adc + kCr) = kCrAdvregen | kCrAdcal;
  if (!wait_clear(adc + kCr, kCrAdcal)) return false;
  reg32(adc + kIsr) = kIsrAdrdy;  // write 1 to clear
  for (uint32_t n = 0; n < kPolls; ++n) {
    reg32(adc + kCr) |= kCrAden;
    if ((reg32(adc + kIsr) & kIsrAdrdy) != 0) return true;
  }
  return false;
}

}  // namespace

AdcInjected::AdcInjected(const AdcInjectedConfig& config) noexcept : config_(config) {
  reg32(kCommonCcr) = (reg32(kCommonCcr) & ~kCkmodeMask) | kCkmodeHclkDiv4;  // ADCs disabled
  const bool up1 = power_up(kAdc1);
  const bool up2 = power_up(kAdc2);
  for (uintptr_t adc : {kAdc1, kAdc2}) reg32(adc + kCfgr) = kCfgrJqdis;
  const uint32_t smp = config_.sampling_time_code;
  set_sampling_time(kAdc1, config_.phase_a_channel, smp);
  set_sampling_time(kAdc1, config_.bus_channel, smp);
  set_sampling_time(kAdc2, config_.phase_b_channel, smp);
  set_sampling_time(kAdc2, config_.phase_c_channel, smp);
  reg32(kAdc1 + kJsqr) = jsqr(config_.phase_a_channel, config_.bus_channel);
  reg32(kAdc2 + kJsqr) = jsqr(config_.phase_b_channel, config_.phase_c_channel);
  reg32(kAdc1 + kCr) |= kCrJadstart;  // armed: converts at each TRGO2 rising edge
  reg32(kAdc2 + kCr) |= kCrJadstart;
  ok_ = up1 && up2;
}

uint32_t AdcInjected::ended_sequences() const noexcept {
  return ((reg32(kAdc1 + kIsr) & kIsrJeos) != 0 ? 1u : 0u) |
         ((reg32(kAdc2 + kIsr) & kIsrJeos) != 0 ? 2u : 0u);
}

void AdcInjected::acknowledge() noexcept {
  reg32(kAdc1 + kIsr) = kIsrJeos;  // write 1 to clear
  reg32(kAdc2 + kIsr) = kIsrJeos;
}

void AdcInjected::latch() noexcept {
  latched_.phase_code[0] = static_cast<uint16_t>(reg32(kAdc1 + kJdr1));
  latched_.bus_code = static_cast<uint16_t>(reg32(kAdc1 + kJdr1 + 4));
  latched_.phase_code[1] = static_cast<uint16_t>(reg32(kAdc2 + kJdr1));
  latched_.phase_code[2] = static_cast<uint16_t>(reg32(kAdc2 + kJdr1 + 4));
}

void AdcInjected::set_interrupt(bool enabled) noexcept {
  for (uintptr_t adc : {kAdc1, kAdc2}) {
    reg32(adc + kIer) = enabled ? (reg32(adc + kIer) | kIsrJeos) : (reg32(adc + kIer) & ~kIsrJeos);
  }
}

}  // namespace imd::hal::cortex_m::stm32g4
