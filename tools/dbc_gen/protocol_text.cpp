#include "protocol_text.hpp"

#include <fmt/format.h>
#include <charconv>
#include <cstdlib>

namespace imd::tools::dbc {

std::string plain_decimal(double value) {
  if (value == 0.0) return "0";  // also -0
  char buffer[400];              // the longest fixed-notation double
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  return std::string(buffer, result.ptr);
}

double decimal(float value) {
  char buffer[64];  // the shortest text that reads back as the float
  const auto result = std::to_chars(buffer, buffer + sizeof buffer - 1, value);
  *result.ptr = '\0';
  return std::strtod(buffer, nullptr);
}

double physical(const Signal& s, int64_t raw) {
  // raw * num and offset * den are exact for table values: one rounding, in the division.
  return (double(raw) * s.scale_num + decimal_offset(s) * s.scale_den) / s.scale_den;
}

std::string type_name(const Signal& s) {
  if (s.is_float) return "float32";
  return fmt::format("{}int{}", s.is_signed ? "" : "u", s.length_bits);
}

std::string value_list(const Signal& s) {
  std::string text;
  for (const auto& v : s.values) {
    if (!text.empty()) text += ", ";
    text += fmt::format("{} {}", v.raw, v.name);
  }
  return text;
}

}  // namespace imd::tools::dbc
