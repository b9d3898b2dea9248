#include "hal/cortex_m/cmsdk_watchdog.hpp"

namespace imd::hal::cortex_m {
namespace {
constexpr uintptr_t kLoad = 0x000, kControl = 0x008, kIntClear = 0x00C, kRawInt = 0x010;
constexpr uintptr_t kLock = 0xC00;
constexpr uint32_t kUnlock = 0x1ACCE551u;
constexpr uint32_t kInterruptEnable = 1u << 0, kResetEnable = 1u << 1;
}  // namespace

CmsdkWatchdog::CmsdkWatchdog(uintptr_t base, uint32_t timeout_counts) noexcept : base_(base) {
  reg(kLock) = kUnlock;
  reg(kLoad) = timeout_counts;  // also restarts the count
  reg(kControl) = kInterruptEnable | kResetEnable;
  reg(kLock) = 0;  // anything but the key locks it
}

void CmsdkWatchdog::feed() noexcept {
  reg(kLock) = kUnlock;
  reg(kIntClear) = 1;  // clears the interrupt and reloads the counter
  reg(kLock) = 0;
}

bool CmsdkWatchdog::expired() const noexcept { return (reg(kRawInt) & 1u) != 0; }

}  // namespace imd::hal::cortex_m
