// The CSV number (csv_number.h) is printf's %.17g text byte for byte: special values, the doubles
// near the format's switch between fixed and exponent notation, and millions of random ones (bit
// patterns, NaN payloads of both signs included, and values across the exponent range).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "birkhoff_cart/core/support/csv_number.h"

namespace birkhoff_cart {
namespace {

std::string printed(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::string appended(double value) {
  std::string text = "x";  // appends, keeping what is there
  append_csv_number(text, value);
  return text.substr(1);
}

TEST(CsvNumber, SpecialValuesAndTheNotationSwitch) {
  const double infinity = std::numeric_limits<double>::infinity();
  for (double value : {0.0, -0.0, 1.0, -1.0, 0.1, 1.0 / 3.0, 1e-300, 5e-324, 2.2250738585072014e-308,
                       1.7976931348623157e308, infinity, -infinity, std::nan(""), -std::nan(""), 1e16, 1e17,
                       99999999999999999.0, 1e-4, 1e-5, 9.9999999999999995e-5, 123456789.123456789}) {
    EXPECT_EQ(appended(value), printed(value)) << printed(value);
  }
  for (int exponent = -330; exponent <= 310; ++exponent) {
    const double value = std::pow(10.0, exponent);
    EXPECT_EQ(appended(value), printed(value)) << exponent;
    EXPECT_EQ(appended(std::nextafter(value, 0.0)), printed(std::nextafter(value, 0.0))) << exponent;
  }
}

TEST(CsvNumber, MillionsOfRandomDoublesAsPrintfWritesThem) {
  std::mt19937_64 generator(20261129);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  int differing = 0;
  std::string first;
  for (int i = 0; i < 1000000; ++i) {
    const std::uint64_t bits = generator();
    double pattern = 0.0;
    std::memcpy(&pattern, &bits, sizeof pattern);
    const double scaled = std::ldexp(mantissa(generator), static_cast<int>(generator() % 200) - 100);
    for (double value : {pattern, scaled}) {
      if (appended(value) != printed(value)) {
        if (differing++ == 0) first = printed(value) + " written as " + appended(value);
      }
    }
  }
  EXPECT_EQ(differing, 0) << "first: " << first;
}

}  // namespace
}  // namespace birkhoff_cart
