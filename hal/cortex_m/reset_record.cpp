#include "hal/cortex_m/reset_record.hpp"

#include <cstdint>

namespace imd::hal::cortex_m {
namespace {

struct Record {
  uint32_t magic;
  uint32_t cause;
};
constexpr uint32_t kMagic = 0x52535421u;  // "RST!"
[[gnu::section(".noinit")]] volatile Record g_record;

}  // namespace

void record_reset_cause(ResetCause cause) noexcept {
  g_record.cause = static_cast<uint32_t>(cause);
  g_record.magic = kMagic;
}

ResetCause take_reset_cause() noexcept {
  const bool valid = g_record.magic == kMagic && g_record.cause <= uint32_t(ResetCause::other);
  const ResetCause cause = valid ? static_cast<ResetCause>(g_record.cause) : ResetCause::power_on;
  g_record.magic = 0;
  return cause;
}

}  // namespace imd::hal::cortex_m
