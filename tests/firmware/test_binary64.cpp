// The motor record's binary64 conversion on the bits (firmware/parameters/binary64.hpp), which
// the MCU uses in place of float <-> double casts: checked here against the host's casts, bit
// for bit, on the edge cases of both formats and on random bit patterns.
#include "firmware/parameters/binary64.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace imd::firmware {
namespace {

uint32_t bits_of(float f) {
  return std::bit_cast<uint32_t>(f);
}

// NaNs compare by class: the cast keeps the payload's top bits and makes the NaN quiet, which
// the conversion does as well; any NaN for a NaN is what the record needs.
void expect_same_float(float expected, float actual, uint64_t from) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(actual)) << std::hex << from;
  } else {
    EXPECT_EQ(bits_of(expected), bits_of(actual)) << std::hex << from << " " << expected;
  }
}

TEST(Binary64, WideningIsTheCastOnEveryKindOfFloat) {
  const float cases[] = {0.0f,
                         -0.0f,
                         1.0f,
                         -1.0f,
                         0.1f,
                         14.0f,
                         0.4128f,
                         1e-30f,
                         std::numeric_limits<float>::min(),
                         std::numeric_limits<float>::max(),
                         std::numeric_limits<float>::denorm_min(),
                         3e-41f,
                         -5e-39f,
                         std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity()};
  for (const float f : cases) {
    EXPECT_EQ(std::bit_cast<uint64_t>(static_cast<double>(f)), binary64_bits(f)) << f;
  }
  EXPECT_TRUE(
      std::isnan(std::bit_cast<double>(binary64_bits(std::numeric_limits<float>::quiet_NaN()))));
}

TEST(Binary64, NarrowingIsTheCastOnTheEdgesOfFloat) {
  const double flt_max = std::numeric_limits<float>::max();
  const double ulp_top = std::ldexp(1.0, 104);  // float's ulp at its largest binade
  const double least = std::numeric_limits<float>::denorm_min();
  const double cases[] = {0.0,
                          -0.0,
                          1.0,
                          0.1,
                          10.1,
                          -0.377,
                          1e-300,
                          1e300,
                          flt_max,
                          flt_max + ulp_top / 2 - std::ldexp(1.0, 70),  // just below the tie
                          flt_max + ulp_top / 2,                        // the tie: overflow
                          least,
                          least / 2,
                          least / 2 * (1 + 1e-15),
                          least * 1.5,
                          least * 2.5,
                          std::numeric_limits<float>::min() * (1 - 1e-9),  // rounds up to normal
                          1 + std::ldexp(1.0, -24),                        // tie to even: 1
                          1 + 3 * std::ldexp(1.0, -24),                    // tie to even: up
                          std::numeric_limits<double>::denorm_min(),
                          std::numeric_limits<double>::infinity(),
                          -std::numeric_limits<double>::infinity()};
  for (const double d : cases) {
    const uint64_t bits = std::bit_cast<uint64_t>(d);
    expect_same_float(static_cast<float>(d), float_from_binary64(bits), bits);
  }
  EXPECT_TRUE(std::isnan(
      float_from_binary64(std::bit_cast<uint64_t>(std::numeric_limits<double>::quiet_NaN()))));
}

// Random doubles over the whole exponent range (uniform bits) and over float's range and just
// beyond it (where the rounding, the subnormals and the overflow are), and every float's
// round trip.
TEST(Binary64, RandomValuesConvertAsTheCasts) {
  std::mt19937_64 rng(20261126);
  for (int k = 0; k < 200000; ++k) {
    const uint64_t bits = rng();
    expect_same_float(static_cast<float>(std::bit_cast<double>(bits)), float_from_binary64(bits),
                      bits);
  }
  std::uniform_int_distribution<int> exponent(1023 - 160, 1023 + 130);
  for (int k = 0; k < 200000; ++k) {
    const uint64_t bits = (rng() & 0x800fffffffffffffULL) | (uint64_t(exponent(rng)) << 52);
    expect_same_float(static_cast<float>(std::bit_cast<double>(bits)), float_from_binary64(bits),
                      bits);
  }
  for (int k = 0; k < 200000; ++k) {
    const float f = std::bit_cast<float>(static_cast<uint32_t>(rng()));
    if (std::isnan(f)) continue;
    EXPECT_EQ(std::bit_cast<uint64_t>(static_cast<double>(f)), binary64_bits(f));
    EXPECT_EQ(bits_of(f), bits_of(float_from_binary64(binary64_bits(f))));
  }
}

}  // namespace
}  // namespace imd::firmware
