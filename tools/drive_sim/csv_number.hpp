#pragma once
/// A double as printf's "%.10g" writes it: the text drive_sim's CSV has always had (fmt's
/// "{:.10g}" is the same). The standard library's std::to_chars with a precision does it
/// without the big-integer fallback fmt takes for a fixed precision: about 60 ns a number
/// against fmt's 90 on the benchmark host, for the same bytes
/// (tests/tools/test_csv_number.cpp compares them).
#include <charconv>

namespace imd::tools {

/// Writes x as "%.10g" at `out` (room for 24 characters: "-1.234567891e-308" is the longest)
/// and returns the end.
inline char* format_g10(double x, char* out) noexcept {
  return std::to_chars(out, out + 24, x, std::chars_format::general, 10).ptr;
}

}  // namespace imd::tools
