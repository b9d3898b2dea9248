#include "hal/cortex_m/stm32g4/tim_encoder.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// TIM2 registers (RM0440 §29.5).
constexpr uintptr_t kCr1 = kTim2 + 0x00;
constexpr uintptr_t kSmcr = kTim2 + 0x08;
constexpr uintptr_t kEgr = kTim2 + 0x14;
constexpr uintptr_t kCcmr1 = kTim2 + 0x18;
constexpr uintptr_t kCcer = kTim2 + 0x20;
constexpr uintptr_t kCnt = kTim2 + 0x24;
constexpr uintptr_t kPsc = kTim2 + 0x28;
constexpr uintptr_t kArr = kTim2 + 0x2C;
constexpr uint32_t kCr1Cen = 1u << 0;
constexpr uint32_t kSmcrEncoderMode3 = 0x3u << 0;  // SMS [2:0] = 011, SMS[3] (bit 16) = 0
// CCMR1 input capture: CC1S [1:0] = 01 (IC1 on TI1), IC1F [7:4]; CC2S [9:8] = 01 (IC2 on TI2),
// IC2F [15:12].
constexpr uint32_t kCcmr1Inputs = (0x1u << 0) | (0x1u << 8);
constexpr uint32_t kCcerCc1e = 1u << 0, kCcerCc1p = 1u << 1, kCcerCc2e = 1u << 4;
constexpr uint32_t kEgrUg = 1u << 0;

}  // namespace

TimEncoder::TimEncoder(const TimEncoderConfig& config) noexcept : config_(config) {
  reg32(kCr1) = 0;
  const uint32_t filter = config_.input_filter & 0xFu;
  reg32(kCcmr1) = kCcmr1Inputs | (filter << 4) | (filter << 12);
  reg32(kCcer) = kCcerCc1e | kCcerCc2e | (config_.reverse ? kCcerCc1p : 0u);
  reg32(kSmcr) = kSmcrEncoderMode3;
  reg32(kPsc) = 0;
  reg32(kArr) = 0xFFFF'FFFFu;  // the whole 32-bit range
  reg32(kEgr) = kEgrUg;
  reg32(kCnt) = 0;
  reg32(kCr1) = kCr1Cen;
}

void TimEncoder::latch() noexcept {
  latched_ = reg32(kCnt);
}

}  // namespace imd::hal::cortex_m::stm32g4
