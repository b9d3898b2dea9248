// The sensor models' Gaussian noise (hal_sim/gaussian_noise.hpp): the sequence the ADC model
// drew before (std::normal_distribution from std::mt19937_64, on GCC's standard library), the
// statistics of a standard normal, tails included, and seeding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "hal_sim/gaussian_noise.hpp"

namespace {

constexpr int kN = 4000000;

#if defined(__GLIBCXX__)
// The same numbers, bit for bit, as the library's polar method on the same seeds: the
// simulated runs did not change. (Another standard library is free to draw otherwise.)
TEST(GaussianNoise, SameSequenceAsTheStandardLibrary) {
  for (const uint64_t seed : {0ull, 1ull, 42ull, 0x9e3779b97f4a7c15ull}) {
    imd::sim::GaussianNoise noise(seed);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    int mismatches = 0;
    for (int i = 0; i < 200000; ++i) {
      const double expected = normal(rng), got = noise();
      if (std::memcmp(&expected, &got, sizeof got) != 0 && ++mismatches < 5) {
        ADD_FAILURE() << "seed " << seed << " draw " << i << ": " << expected << " " << got;
      }
    }
    EXPECT_EQ(mismatches, 0);
  }
}
#endif

// Each bound is five standard errors of its estimate for a true standard normal over N = 4e6
// draws, so a correct generator fails one with probability below 1e-6 per check (and the
// seed is fixed): the mean 1/sqrt(N) = 5e-4; the variance sqrt(2/N) = 7.1e-4; the fourth
// moment (3) sqrt((105 - 9)/N) = 4.9e-3; a share p of the draws sqrt(p (1 - p)/N).
TEST(GaussianNoise, StandardNormalStatistics) {
  imd::sim::GaussianNoise noise(7);
  // The CDF at these points, from the tails to the mean.
  const double points[] = {-4.0, -3.4, -2.0, -1.0, -0.3, 0.0, 0.5, 1.0, 1.7, 2.5, 3.4, 4.0};
  constexpr int kPoints = sizeof points / sizeof points[0];
  int below[kPoints] = {};
  double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
  for (int n = 0; n < kN; ++n) {
    const double x = noise();
    sum += x;
    sum2 += x * x;
    sum4 += x * x * x * x;
    for (int j = 0; j < kPoints; ++j) below[j] += x < points[j] ? 1 : 0;
  }
  const double mean = sum / kN;
  EXPECT_NEAR(mean, 0.0, 5 * 5e-4);
  EXPECT_NEAR(sum2 / kN - mean * mean, 1.0, 5 * 7.1e-4);
  EXPECT_NEAR(sum4 / kN, 3.0, 5 * 4.9e-3);
  for (int j = 0; j < kPoints; ++j) {
    const double p = 0.5 * std::erfc(-points[j] / std::sqrt(2.0));
    EXPECT_NEAR(double(below[j]) / kN, p, 5 * std::sqrt(p * (1 - p) / kN)) << "at " << points[j];
  }
}

// Consecutive draws are uncorrelated: the lag-1 correlation of independent normals has the
// standard error 1/sqrt(N) = 5e-4.
TEST(GaussianNoise, SuccessiveDrawsUncorrelated) {
  imd::sim::GaussianNoise noise(11);
  double last = noise(), sum = 0.0;
  for (int n = 0; n < kN; ++n) {
    const double x = noise();
    sum += x * last;
    last = x;
  }
  EXPECT_NEAR(sum / kN, 0.0, 5 * 5e-4);
}

// Reproducible: the same seed, the same numbers; another seed, others.
TEST(GaussianNoise, SeededReproducibly) {
  imd::sim::GaussianNoise a(3), b(3), c(4);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = a(), y = b(), z = c();
    EXPECT_EQ(x, y);
    differ += x != z ? 1 : 0;
  }
  EXPECT_GT(differ, 990);  // two independent normals coincide with probability zero
}

}  // namespace
