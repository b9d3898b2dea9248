// drive_sim's number formatting (tools/drive_sim/csv_number.hpp) against fmt's
// "{:.10g}", the text its CSV had before: byte for byte, on every kind of double (random bit
// patterns cover every exponent), on values near the ties and decade boundaries where two
// shortest-digit algorithms could round differently, and on the magnitudes of a simulation row.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "tools/drive_sim/csv_number.hpp"

namespace {

std::string fast(double x) {
  // The contract gives format_g10 24 characters of room: nothing may be written past them.
  char text[40];
  std::memset(text, '#', sizeof text);
  char* end = imd::tools::format_g10(x, text);
  for (std::size_t i = 24; i < sizeof text; ++i) {
    if (text[i] != '#') ADD_FAILURE() << "wrote past 24 characters for " << x;
  }
  return std::string(text, std::size_t(end - text));
}

TEST(CsvNumber, SameTextAsFmt) {
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal;
  int mismatches = 0;
  const auto check = [&](double x) {
    const std::string expected = fmt::format("{:.10g}", x);
    if (fast(x) != expected && ++mismatches < 10) ADD_FAILURE() << expected << " " << fast(x);
  };
  for (double x : {0.0, -0.0, 1.0, -1.0, 0.1, 0.2, 1e-5, 1e-4, 9.9999999995, 9.99999999949999,
                   99999.999995, 1e10, 9999999999.5, 9999999999.4, 0.5, 2.5, 1.25e-5,
                   std::nan(""), -double(INFINITY), 5e-324, 1e300}) {
    check(x);
  }
  for (int i = 0; i < 300000; ++i) {
    uint64_t bits = random();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    check(x);                                                       // any double
    check(normal(random) * std::pow(10.0, int(random() % 50) - 20));  // any magnitude
    // Exact ties at the tenth digit, and integers and binary fractions of 10 to 11 digits.
    const double base = double(int64_t(random() % 20000000000ull) - 10000000000ll);
    check(base + 0.5);
    check((base + 0.5) * 1e-5);
    check(base / 1024.0);
    // The same ties at every decade of the fast path (1e-13 to 1e9), and their neighbours a
    // few ulps away, on either side of the margin where it hands over to the exact path.
    const double tie = (base + 0.5) * std::pow(10.0, -int(random() % 24));
    check(tie);
    check(std::nextafter(tie, 0.0));
    check(std::nextafter(std::nextafter(std::nextafter(tie, INFINITY), INFINITY), INFINITY));
    // Powers of ten and their neighbours (the decade boundaries).
    const double power = std::pow(10.0, int(random() % 40) - 15);
    check(power);
    check(std::nextafter(power, 0.0));
    check(std::nextafter(power, INFINITY));
  }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
