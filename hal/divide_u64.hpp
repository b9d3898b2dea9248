#pragma once
/// A 64-bit quotient by a 32-bit divisor with 32-bit divisions only. On the Cortex-M4 a 64-bit
/// `/` is libgcc's __udivmoddi4 (700 B of flash, a hundred cycles and more); UDIV divides 32
/// bits in 2 to 12 cycles. Used where the MCU divides a tick count or a product of two 32-bit
/// values: the telemetry's milliseconds (in the tick), the watchdog's reload and the PWM's dead
/// time (at start-up).
#include <bit>
#include <cstdint>

namespace imd::hal {

/// n / d, rounded down (all ones for d = 0). Long division in chunks of c = countl_zero(d)
/// bits: each step divides the last remainder (r < d < 2^(32 - c)) shifted up by c bits, plus
/// the next c bits of n, which stays below 2^32. For a divisor of 10^6 that is six steps of 12
/// bits. A divisor of 2^31 or more leaves no room for a chunk: one bit at a time, in 64 bits.
constexpr uint64_t divide_u64(uint64_t n, uint32_t d) noexcept {
  if (d == 0) return ~uint64_t(0);
  const int chunk = std::countl_zero(d);
  if (chunk == 0) {
    uint64_t q = 0, r = 0;
    for (int bit = 63; bit >= 0; --bit) {
      r = (r << 1) | ((n >> bit) & 1u);
      q <<= 1;
      if (r >= d) {
        r -= d;
        q |= 1u;
      }
    }
    return q;
  }
  const uint32_t mask = (uint32_t(1) << chunk) - 1u;
  uint64_t q = 0;
  uint32_t r = 0;
  for (int shift = 63 / chunk * chunk; shift >= 0; shift -= chunk) {  // the top chunk first
    const uint32_t part = (r << chunk) | (uint32_t(n >> shift) & mask);
    q = (q << chunk) | (part / d);
    r = part % d;
  }
  return q;
}

static_assert(divide_u64(0xFFFF'FFFF'FFFF'FFFFull, 1'000'000u) == 18'446'744'073'709ull);
static_assert(divide_u64(0xFFFF'FFFF'FFFF'FFFFull, 1u) == 0xFFFF'FFFF'FFFF'FFFFull);
static_assert(divide_u64(0x7FFF'FFFF'FFFF'FFFFull, 0x7FFF'FFFFu) == 0x1'0000'0002ull);
static_assert(divide_u64(0xFFFF'FFFF'FFFF'FFFFull, 0xFFFF'FFFFu) == 0x1'0000'0001ull);

}  // namespace imd::hal
