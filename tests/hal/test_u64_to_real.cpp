#include "hal/u64_to_real.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace imd::hal {
namespace {

TEST(U64ToReal, ExactBelowTwoToTheTwentyFourInFloat) {
  for (uint64_t x = 0; x < (uint64_t{1} << 24); x += 997) {
    ASSERT_EQ(u64_to_real<float>(x), static_cast<float>(x)) << x;
  }
  EXPECT_EQ(u64_to_real<float>((uint64_t{1} << 24) - 1), 16777215.0f);
}

TEST(U64ToReal, ExactBelowTwoToTheFiftyThreeInDouble) {
  std::mt19937_64 random(7);
  for (int i = 0; i < 1'000'000; ++i) {
    const uint64_t x = random() >> 11;
    ASSERT_EQ(u64_to_real<double>(x), static_cast<double>(x)) << x;
  }
}

TEST(U64ToReal, WithinOneUlpOfTheRoundedValueAnywhereInFloat) {
  // Every magnitude: random 64-bit values shifted down by 0 to 63 bits, and the halves' edges.
  std::mt19937_64 random(11);
  auto check = [](uint64_t x) {
    const float direct = static_cast<float>(x);
    const float halves = u64_to_real<float>(x);
    const float ulp = std::nextafter(direct, INFINITY) - direct;
    ASSERT_LE(std::fabs(halves - direct), ulp) << x;
  };
  for (int i = 0; i < 1'000'000; ++i) check(random() >> (i % 64));
  for (const uint64_t x : {~uint64_t{0}, uint64_t{0xFFFFFFFF}, uint64_t{1} << 32,
                           (uint64_t{1} << 32) + 0xFFFFFFFF, uint64_t{0x00FFFFFF80000000}}) {
    check(x);
  }
}

}  // namespace
}  // namespace imd::hal
