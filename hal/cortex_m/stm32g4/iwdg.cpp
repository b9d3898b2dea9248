#include "hal/cortex_m/stm32g4/iwdg.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"
#include "hal/divide_u64.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

constexpr uintptr_t kKr = kIwdg + 0x00, kPr = kIwdg + 0x04, kRlr = kIwdg + 0x08;
constexpr uintptr_t kSr = kIwdg + 0x0C;
constexpr uint32_t kKeyStart = 0xCCCC, kKeyUnlock = 0x5555, kKeyFeed = 0xAAAA;
constexpr uint32_t kLsi_Hz = 32'000;
constexpr uint32_t kPrescaler4 = 0;  // PR = 0: LSI / 4, 8 kHz, 125 us per count
constexpr uint32_t kSrBusy = 0x7;    // PVU, RVU, WVU: an update is still being taken

constexpr uintptr_t kRccCsr = kRcc + 0x94;
constexpr uint32_t kCsrRmvf = 1u << 23;
constexpr uint32_t kCsrPin = 1u << 26, kCsrBor = 1u << 27, kCsrSoftware = 1u << 28;
constexpr uint32_t kCsrIwdg = 1u << 29, kCsrWwdg = 1u << 30;

}  // namespace

void Iwdg::start(uint32_t timeout_us) noexcept {
  const uint32_t counts_per_s = kLsi_Hz / 4;
  uint32_t reload = uint32_t(divide_u64(uint64_t(timeout_us) * counts_per_s, 1'000'000u));
  reload = reload < 1 ? 1 : (reload > 0xFFF ? 0xFFF : reload);
  reg32(kKr) = kKeyStart;   // starts it (and the LSI)
  reg32(kKr) = kKeyUnlock;  // PR and RLR writable
  reg32(kPr) = kPrescaler4;
  reg32(kRlr) = reload;
  for (uint32_t n = 0; n < 1'000'000 && (reg32(kSr) & kSrBusy) != 0; ++n) {
  }  // 5 LSI cycles, 160 us; bounded: a stuck update still leaves the watchdog running
  reg32(kKr) = kKeyFeed;  // reloads the counter, and locks PR and RLR again
}

void Iwdg::feed() noexcept { reg32(kKr) = kKeyFeed; }

hal::ResetCause take_reset_cause() noexcept {
  const uint32_t csr = reg32(kRccCsr);
  reg32(kRccCsr) = csr | kCsrRmvf;
  if ((csr & (kCsrIwdg | kCsrWwdg)) != 0) return hal::ResetCause::watchdog;
  if ((csr & kCsrSoftware) != 0) return hal::ResetCause::software;
  if ((csr & (kCsrBor | kCsrPin)) != 0) return hal::ResetCause::power_on;
  return hal::ResetCause::other;
}

}  // namespace imd::hal::cortex_m::stm32g4
