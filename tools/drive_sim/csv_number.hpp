#pragma once
/// A double as printf's "%.10g" writes it: the text drive_sim's CSV has always had (fmt's
/// "{:.10g}" is the same), byte for byte (tests/tools/test_csv_number.cpp compares them).
///
/// The fast path scales |x| by an exact power of ten into [1e9, 1e10) with one IEEE
/// multiplication or division, so the scaled value is the exact one correctly rounded: off by
/// at most half an ulp of 1e10, 9.5e-7. Its nearest integer is then the exact value's ten
/// significant digits unless the fraction lies within that error of one half (a possible tie)
/// or the value within it of a decade's end: those, and magnitudes outside about 1e-13 to 1e9
/// (where the powers of ten used would not be exact), take std::to_chars with a precision,
/// which is exact but slower (it works through the value's full binary expansion).
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace imd::tools {
namespace csv_number_detail {

/// 10^0 to 10^22: every one exactly a double.
inline constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// Writes v < 100000 as five decimal digits.
inline void write_5_digits(uint32_t v, char* d) noexcept {
  static constexpr char kPairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  const uint32_t high = v / 1000, low = v % 1000;  // high < 100
  std::memcpy(d, kPairs + 2 * high, 2);
  d[2] = char('0' + low / 100);
  std::memcpy(d + 3, kPairs + 2 * (low % 100), 2);
}

/// The fast path: nullptr when it cannot decide (see the file's comment).
inline char* format_g10_fast(double x, char* out) noexcept {
  // A safe margin over the 9.5e-7 error bound: a fraction this close to one half, or a value
  // this close to a decade's end, goes to the exact path.
  constexpr double kMargin = 1e-5;
  if (!std::isfinite(x) || x == 0.0) return nullptr;
  const double a = std::fabs(x);
  // k = floor(e2 log10 2) for a = m 2^e2, m in [1, 2): the decade of a or the one below it.
  const int e2 = int((std::bit_cast<uint64_t>(a) >> 52) & 0x7ff) - 1023;  // a is not 0
  int k = e2 * 30103 / 100000 - (e2 < 0 ? 1 : 0);  // the division truncates towards zero
  // Scaled for both candidates, one picked without a branch: random digits defeat a predictor.
  const int p = 9 - k;
  if (p < 1 || p > 22) return nullptr;  // the powers of ten must be exact
  const double s_low = a * kPow10[p], s_high = a * kPow10[p - 1];
  const bool up = s_low >= 1e10;
  k += up ? 1 : 0;
  const double s = up ? s_high : s_low;
  if (s < 1e9 + kMargin || s > 1e10 - kMargin) return nullptr;
  auto digits = static_cast<uint64_t>(s);                   // s > 0: truncation is the floor
  const double fraction = s - static_cast<double>(digits);  // exact: both multiples of s's ulp
  if (std::fabs(fraction - 0.5) < kMargin) return nullptr;
  digits += fraction > 0.5 ? 1 : 0;
  if (digits == 10000000000ull) {  // rounded up into the next decade
    digits = 1000000000ull;
    ++k;
  }
  char d[10];
  write_5_digits(uint32_t(digits / 100000), d);  // two independent halves: shorter chains
  write_5_digits(uint32_t(digits % 100000), d + 5);
  int n = 10;  // significant digits without trailing zeros
  while (d[n - 1] == '0') --n;
  if (x < 0) *out++ = '-';
  if (k < -4 || k >= 10) {  // d.ddde+XX, as %g does for these exponents
    *out++ = d[0];
    if (n > 1) {
      *out++ = '.';
      std::memcpy(out, d + 1, std::size_t(n - 1));
      out += n - 1;
    }
    *out++ = 'e';
    *out++ = k < 0 ? '-' : '+';
    const int e = k < 0 ? -k : k;  // below 100 on this path
    *out++ = char('0' + e / 10);
    *out++ = char('0' + e % 10);
  } else if (k >= 0) {  // ddd.ddd
    std::memcpy(out, d, std::size_t(k + 1));
    out += k + 1;
    if (n > k + 1) {
      *out++ = '.';
      std::memcpy(out, d + k + 1, std::size_t(n - k - 1));
      out += n - k - 1;
    }
  } else {  // 0.000ddd
    *out++ = '0';
    *out++ = '.';
    for (int i = -1; i > k; --i) *out++ = '0';
    std::memcpy(out, d, std::size_t(n));
    out += n;
  }
  return out;
}

}  // namespace csv_number_detail

/// Writes x as "%.10g" at `out` (room for 24 characters: "-1.234567891e-308" is the longest)
/// and returns the end.
inline char* format_g10(double x, char* out) noexcept {
  if (char* end = csv_number_detail::format_g10_fast(x, out)) return end;
  return std::to_chars(out, out + 24, x, std::chars_format::general, 10).ptr;
}

}  // namespace imd::tools
