// Durations in ticks (firmware/duration_ticks.hpp), in the design arithmetic: the host's double
// and, in the float-design build, the MCU's float.
#include "firmware/duration_ticks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace imd::firmware {
namespace {

// Durations and periods as a configuration writes them (decimal), every duration a whole
// number of every period.
constexpr double kPeriods_s[] = {1e-4, 5e-5, 2e-4, 1.25e-4, 1e-3};
constexpr double kDurations_s[] = {0.002, 0.02, 0.2, 1.0, 2.5, 30.0, 210.0, 1000.0, 86400.0};

TEST(DurationTicks, AWholeNumberOfPeriodsIsThatNumber) {
  const double eps = std::numeric_limits<Real>::epsilon();
  for (const double period_s : kPeriods_s) {
    for (const double duration_s : kDurations_s) {
      const double exact = std::round(duration_s / period_s);
      const auto ticks = double(duration_ticks(Real(duration_s), Real(period_s)));
      if (exact <= 2097152.0) {  // 2^21: Real resolves the quotient to better than half a tick
        EXPECT_EQ(ticks, exact) << duration_s << " s at " << period_s << " s";
      } else {  // the parameters' and the division's rounding, half an epsilon each
        EXPECT_LE(std::abs(ticks - exact), 1.5 * eps * exact + 1)
            << duration_s << " s at " << period_s << " s";
      }
    }
  }
}

TEST(DurationTicks, APartTickRoundsUp) {
  for (const double period_s : kPeriods_s) {
    for (const double n : {0.0, 1.0, 7.0, 199.0, 4321.0, 1e5}) {
      const Real duration_s = Real((n + 0.3) * period_s);
      EXPECT_EQ(duration_ticks(duration_s, Real(period_s)), uint64_t(n) + 1) << n;
    }
  }
}

TEST(DurationTicks, NoneAndForever) {
  EXPECT_EQ(duration_ticks(0, Real(1e-4)), 0u);
  EXPECT_EQ(duration_ticks(-1, Real(1e-4)), 0u);
  EXPECT_EQ(duration_ticks(std::numeric_limits<Real>::quiet_NaN(), Real(1e-4)), 0u);
  EXPECT_EQ(duration_ticks(std::numeric_limits<Real>::infinity(), Real(1e-4)), UINT64_MAX);
}

}  // namespace
}  // namespace imd::firmware
