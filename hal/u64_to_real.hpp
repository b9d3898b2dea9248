#pragma once
/// An unsigned 64-bit count as a float or double by its two 32-bit halves. On the Cortex-M4 a
/// 64-bit integer's conversion to float is libgcc's __aeabi_ul2f, which also links the
/// soft-float addition it is written with (800 B of flash in all); each half is one VCVT. Used
/// for the MCU's sums and counts (the tick's mean execution time, the ADC offset calibration).
///
/// Exact below 2^24 in float (the high half is zero) and below 2^53 in double. Above 2^24 in
/// float the low half and the sum are each rounded: within one ulp of the directly rounded
/// value (tests/hal/test_u64_to_real.cpp).
#include <cstdint>
#include <type_traits>

namespace imd::hal {

template <typename T>
constexpr T u64_to_real(uint64_t x) noexcept {
  static_assert(std::is_floating_point_v<T>, "u64_to_real<float or double>");
  return T(static_cast<uint32_t>(x >> 32)) * T(4294967296.0) + T(static_cast<uint32_t>(x));
}

}  // namespace imd::hal
