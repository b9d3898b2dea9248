#pragma once
/// A parameter as IEEE 754 binary64 bits and back: the motor record's field format, one for
/// every target. The host's parameters are double, whose bits these are; the MCU's are float
/// (control/real.hpp), and a float <-> double cast there would link the soft-double library for
/// a change of format only. So the conversion works on the bits: widening is exact, and
/// narrowing rounds to nearest, ties to even, as a cast does (overflow to infinity, underflow to
/// subnormals or zero, NaN stays NaN). tests/firmware/test_binary64.cpp checks both directions
/// against the compiler's casts, bit for bit.
#include <bit>
#include <cstdint>
#include <type_traits>

#include "control/real.hpp"

namespace imd::firmware {

/// The binary64 bits of a float's value (exact).
constexpr uint64_t binary64_bits(float value) noexcept {
  const uint32_t bits = std::bit_cast<uint32_t>(value);
  const uint64_t sign = uint64_t(bits >> 31) << 63;
  int exponent = int(bits >> 23) & 0xff;
  uint64_t mantissa = bits & 0x7fffffu;
  if (exponent == 0xff) return sign | (uint64_t(0x7ff) << 52) | (mantissa << 29);  // inf, NaN
  if (exponent == 0) {
    if (mantissa == 0) return sign;  // +-0
    exponent = 1;                    // subnormal: normalize (binary64 has the range)
    while ((mantissa & 0x800000u) == 0) {
      mantissa <<= 1;
      --exponent;
    }
    mantissa &= 0x7fffffu;
  }
  return sign | (uint64_t(exponent - 127 + 1023) << 52) | (mantissa << 29);
}

/// The float nearest to a binary64 value (ties to even), as static_cast<float> gives it.
constexpr float float_from_binary64(uint64_t bits) noexcept {
  const uint32_t sign = uint32_t(bits >> 63) << 31;
  const int exponent = int(bits >> 52) & 0x7ff;
  const uint64_t fraction = bits & ((uint64_t(1) << 52) - 1);
  if (exponent == 0x7ff) {  // inf, or NaN made quiet with its payload's top bits
    return std::bit_cast<float>(sign | 0x7f800000u |
                                (fraction ? 0x400000u | uint32_t(fraction >> 29) : 0u));
  }
  if (exponent == 0) return std::bit_cast<float>(sign);  // below 2^-1022: rounds to zero
  const int unbiased = exponent - 1023;
  const uint64_t significand = (uint64_t(1) << 52) | fraction;  // 53 bits
  // A normal float keeps 24 of the 53 bits; a subnormal one fewer, down to none.
  const int shift = unbiased >= -126 ? 29 : 29 + (-126 - unbiased);
  if (shift > 54) return std::bit_cast<float>(sign);  // less than half the least subnormal
  uint64_t kept = significand >> shift;
  const uint64_t rest = significand & ((uint64_t(1) << shift) - 1);
  const uint64_t half = uint64_t(1) << (shift - 1);
  if (rest > half || (rest == half && (kept & 1))) ++kept;
  if (unbiased < -126) return std::bit_cast<float>(sign | uint32_t(kept));  // may reach 2^-126
  int biased = unbiased + 127;
  if (kept == (uint64_t(1) << 24)) {  // rounded up to the next power of two
    kept >>= 1;
    ++biased;
  }
  if (biased >= 0xff) return std::bit_cast<float>(sign | 0x7f800000u);  // overflow
  return std::bit_cast<float>(sign | (uint32_t(biased) << 23) | (uint32_t(kept) & 0x7fffffu));
}

/// A parameter's record bits.
inline uint64_t record_bits(double value) noexcept {
  return std::bit_cast<uint64_t>(value);
}
inline uint64_t record_bits(float value) noexcept {
  return binary64_bits(value);
}

/// A parameter from its record bits.
template <typename R = Real>
R record_value(uint64_t bits) noexcept {
  if constexpr (std::is_same_v<R, double>) {
    return std::bit_cast<double>(bits);
  } else {
    return float_from_binary64(bits);
  }
}

}  // namespace imd::firmware
