#include "hal/cortex_m/text_line.hpp"

#include <cmath>

namespace imd::hal::cortex_m {

TextLine& TextLine::operator<<(std::string_view text) noexcept {
  for (const char c : text) put(c);
  return *this;
}

TextLine& TextLine::operator<<(uint64_t value) noexcept {
  char digits[20];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (n > 0) put(digits[--n]);
  return *this;
}

TextLine& TextLine::operator<<(int64_t value) noexcept {
  if (value < 0) {
    put('-');
    return *this << (~static_cast<uint64_t>(value) + 1);
  }
  return *this << static_cast<uint64_t>(value);
}

TextLine& TextLine::scientific(double value, int significant) noexcept {
  if (std::isnan(value)) return *this << "nan";
  if (std::isinf(value)) return *this << (value > 0 ? "inf" : "-inf");
  if (significant < 1) significant = 1;
  if (significant > 17) significant = 17;
  if (std::signbit(value)) {
    put('-');
    value = -value;
  }
  int exponent = 0;
  uint64_t mantissa = 0;  // `significant` digits
  if (value != 0.0) {
    exponent = static_cast<int>(std::floor(std::log10(value)));
    // Digits by rounding value / 10^(exponent - significant + 1); a carry adds a digit.
    const double scaled = value * std::pow(10.0, significant - 1 - exponent);
    mantissa = static_cast<uint64_t>(std::llround(scaled));
    uint64_t limit = 1;
    for (int i = 0; i < significant; ++i) limit *= 10;
    if (mantissa >= limit) {
      mantissa /= 10;
      ++exponent;
    }
  }
  char digits[17];
  for (int i = significant - 1; i >= 0; --i) {
    digits[i] = static_cast<char>('0' + mantissa % 10);
    mantissa /= 10;
  }
  put(digits[0]);
  if (significant > 1) {
    put('.');
    for (int i = 1; i < significant; ++i) put(digits[i]);
  }
  put('e');
  put(exponent < 0 ? '-' : '+');
  const int magnitude = exponent < 0 ? -exponent : exponent;
  if (magnitude < 10) put('0');
  return *this << static_cast<uint64_t>(magnitude);
}

}  // namespace imd::hal::cortex_m
