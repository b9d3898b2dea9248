// hal/divide_u64.hpp against the compiler's 64-bit division: every chunk size (divisors of
// each bit length), the edges of both operands, and random pairs.
#include "hal/divide_u64.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

namespace imd::hal {
namespace {

TEST(DivideU64, EqualsTheLibraryDivisionForEveryDivisorLength) {
  std::mt19937_64 rng(20261126);
  const uint64_t edges[] = {0, 1, 2, 0xFFFF'FFFFull, 0x1'0000'0000ull, 0x7FFF'FFFF'FFFF'FFFFull,
                            0x8000'0000'0000'0000ull, ~uint64_t(0)};
  for (int bits = 1; bits <= 32; ++bits) {  // divisors of each length: every chunk size
    const uint32_t top = uint32_t(1) << (bits - 1);
    const uint32_t divisors[] = {top, uint32_t(top | (top - 1)), uint32_t(top | (rng() & (top - 1)))};
    for (const uint32_t d : divisors) {
      for (const uint64_t n : edges) EXPECT_EQ(divide_u64(n, d), n / d) << n << " / " << d;
      for (int i = 0; i < 200; ++i) {
        const uint64_t n = rng() >> (rng() % 64);  // every magnitude
        ASSERT_EQ(divide_u64(n, d), n / d) << n << " / " << d;
      }
    }
  }
}

TEST(DivideU64, TheFirmwaresDivisorsAreExact) {
  // Milliseconds from a tick count at 20 kHz, 10 kHz and an odd period, past 2^32 ms.
  for (const uint32_t period_ns : {50'000u, 100'000u, 123'457u}) {
    for (const uint64_t tick : {uint64_t(0), uint64_t(9'999), uint64_t(1) << 40}) {
      EXPECT_EQ(divide_u64(tick * period_ns, 1'000'000u), tick * period_ns / 1'000'000u);
    }
  }
  // The dead time in timer counts, rounded up: 1 us at 170 MHz is 170 counts exactly, 333 ns
  // is 56.61 counts, so 57.
  EXPECT_EQ(divide_u64(uint64_t(1'000) * 170'000'000u + 999'999'999u, 1'000'000'000u), 170u);
  EXPECT_EQ(divide_u64(uint64_t(333) * 170'000'000u + 999'999'999u, 1'000'000'000u), 57u);
}

TEST(DivideU64, AZeroDivisorGivesAllOnesRatherThanATrap) {
  EXPECT_EQ(divide_u64(5, 0), ~uint64_t(0));
}

}  // namespace
}  // namespace imd::hal
