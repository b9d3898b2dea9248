#include "hal/cortex_m/stm32g4/flash_pages.hpp"

#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// Flash interface registers (RM0440 §5.7).
constexpr uintptr_t kAcr = kFlash + 0x00;
constexpr uintptr_t kKeyr = kFlash + 0x08;
constexpr uintptr_t kSr = kFlash + 0x10;
constexpr uintptr_t kCr = kFlash + 0x14;
constexpr uint32_t kKey1 = 0x4567'0123, kKey2 = 0xCDEF'89AB;  // §5.5.1
constexpr uint32_t kCrPg = 1u << 0, kCrPer = 1u << 1, kCrPnbShift = 3, kCrPnbMask = 0x7Fu << 3;
constexpr uint32_t kCrStrt = 1u << 16, kCrLock = 1u << 31;
constexpr uint32_t kSrEop = 1u << 0, kSrBsy = 1u << 16;
// OPERR, PROGERR, WRPERR, PGAERR, SIZERR, PGSERR, MISERR, FASTERR, RDERR, OPTVERR.
constexpr uint32_t kSrErrors = (1u << 1) | (0x7Fu << 3) | (1u << 14) | (1u << 15);
constexpr uint32_t kAcrDcen = 1u << 10, kAcrDcrst = 1u << 12;
// A bound on the busy wait: 40 ms of erase at 170 MHz is under 7e6 cycles; the loop takes
// more than one cycle per turn.
constexpr uint32_t kBusySpins = 10'000'000;

uintptr_t page_address(int page) noexcept {
  return kParameterPage0 + static_cast<uintptr_t>(page) * kFlashPageBytes;
}

/// The data cache may hold the page's old content (RM0440 §3.3.4): reset it after a change.
void flush_data_cache() noexcept {
  reg32(kAcr) &= ~kAcrDcen;
  reg32(kAcr) |= kAcrDcrst;
  reg32(kAcr) &= ~kAcrDcrst;
  reg32(kAcr) |= kAcrDcen;
}

}  // namespace

bool FlashPagePair::unlock() noexcept {
  if ((reg32(kCr) & kCrLock) != 0) {
    reg32(kKeyr) = kKey1;
    reg32(kKeyr) = kKey2;
  }
  reg32(kSr) = kSrErrors | kSrEop;  // write 1 to clear what an earlier operation left
  return (reg32(kCr) & kCrLock) == 0;
}

void FlashPagePair::lock() noexcept {
  reg32(kCr) |= kCrLock;
}

bool FlashPagePair::wait_done() noexcept {
  for (uint32_t spin = 0; (reg32(kSr) & kSrBsy) != 0; ++spin) {
    if (spin >= kBusySpins) {
      last_error_ = kSrBsy;
      return false;
    }
  }
  const uint32_t errors = reg32(kSr) & kSrErrors;
  reg32(kSr) = errors | kSrEop;
  if (errors != 0) last_error_ = errors;
  return errors == 0;
}

bool FlashPagePair::erase(int page) noexcept {
  if (page != 0 && page != 1) return false;
  if (!unlock()) return false;
  const uint32_t pnb = (kParameterFirstPage + static_cast<uint32_t>(page)) << kCrPnbShift;
  reg32(kCr) = (reg32(kCr) & ~(kCrPnbMask | kCrPg)) | kCrPer | pnb;
  reg32(kCr) |= kCrStrt;
  const bool ok = wait_done();
  reg32(kCr) &= ~(kCrPer | kCrPnbMask);
  lock();
  flush_data_cache();
  return ok;
}

bool FlashPagePair::program(int page, std::size_t offset, std::span<const uint8_t> bytes) noexcept {
  if ((page != 0 && page != 1) || offset % 8 != 0 || bytes.size() % 8 != 0 ||
      offset + bytes.size() > kFlashPageBytes) {
    return false;
  }
  if (!unlock()) return false;
  reg32(kCr) |= kCrPg;
  bool ok = true;
  for (std::size_t i = 0; ok && i < bytes.size(); i += 8) {
    uint32_t words[2] = {0, 0};
    for (int b = 0; b < 8; ++b) words[b / 4] |= uint32_t(bytes[i + b]) << (8 * (b % 4));
    const uintptr_t address = page_address(page) + offset + i;
    reg32(address) = words[0];  // the double word is programmed once both halves are written
    reg32(address + 4) = words[1];
    ok = wait_done();
  }
  reg32(kCr) &= ~kCrPg;
  lock();
  flush_data_cache();
  return ok;
}

void FlashPagePair::read(int page, std::size_t offset, std::span<uint8_t> out) const noexcept {
  for (std::size_t i = 0; i < out.size(); ++i) {
    const bool inside = (page == 0 || page == 1) && offset + i < kFlashPageBytes;
    out[i] = inside ? *reinterpret_cast<const volatile uint8_t*>(page_address(page) + offset + i)
                    : uint8_t{0xFF};
  }
}

}  // namespace imd::hal::cortex_m::stm32g4
