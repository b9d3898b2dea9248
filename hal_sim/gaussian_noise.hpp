#pragma once
/// Standard normal numbers for the sensor models, from a 64-bit Mersenne Twister with
/// Marsaglia's polar method, both values of each accepted pair used: the sequence
/// std::normal_distribution<double>(0, 1) of GCC's libstdc++ draws from std::mt19937_64 with
/// the same seed, number for number (tests/hal_sim/test_gaussian_noise.cpp), written out so
/// that the library's generic uniform (std::generate_canonical, which works in long double)
/// and its parameter handling are not paid four times a tick. Header-only: the board's models
/// call it inline. No heap.
#include <cmath>
#include <cstdint>
#include <random>

namespace imd::sim {

class GaussianNoise {
 public:
  explicit GaussianNoise(uint64_t seed) noexcept : rng_(seed) {}

  /// The next standard normal number.
  double operator()() noexcept {
    if (saved_available_) {
      saved_available_ = false;
      return saved_ + 0.0;  // as the library's `x * stddev + mean`: -0 becomes +0
    }
    double x = 0.0, y = 0.0, r2 = 0.0;
    do {
      x = 2.0 * uniform() - 1.0;
      y = 2.0 * uniform() - 1.0;
      r2 = x * x + y * y;
    } while (r2 > 1.0 || r2 == 0.0);
    const double mult = std::sqrt(-2.0 * std::log(r2) / r2);
    saved_ = x * mult;
    saved_available_ = true;
    return y * mult + 0.0;
  }

 private:
  /// In [0, 1): one 64-bit draw over 2^64 (exact but for the draw's rounding to 53 bits),
  /// the largest double below 1 where that rounding reaches 1.
  double uniform() noexcept {
    const double u = static_cast<double>(rng_()) * 0x1p-64;
    return u < 1.0 ? u : 0x1.fffffffffffffp-1;
  }

  std::mt19937_64 rng_;
  double saved_ = 0.0;
  bool saved_available_ = false;
};

}  // namespace imd::sim
