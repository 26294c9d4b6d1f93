#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/mesh/decimal_format.h"

namespace mq {
namespace {

std::string formatted(double v, int precision) {
  char buffer[40];
  return std::string(buffer, format_decimal(buffer, v, precision));
}

std::string reference(double v, int precision) {
  char buffer[40];
  const auto r = precision <= 0 ? std::to_chars(buffer, buffer + 40, v)
                                : std::to_chars(buffer, buffer + 40, v, std::chars_format::general,
                                                std::min(precision, 17));
  return std::string(buffer, r.ptr);
}

// Every value the writers may meet, against std::to_chars at the same precision: values of
// every magnitude the fast path takes and around it, with 1 to 17 digits.
TEST(DecimalFormat, EqualsToCharsOnRandomValuesOfEveryMagnitude) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::uniform_int_distribution<int> exponent(-8, 18);
  int mismatches = 0;
  for (int i = 0; i < 400000; ++i) {
    const double v = (i % 2 ? -1 : 1) * mantissa(rng) * std::pow(10.0, exponent(rng));
    const int precision = 1 + i % 17;
    if (formatted(v, precision) != reference(v, precision) && ++mismatches < 10)
      ADD_FAILURE() << v << " at " << precision << ": " << formatted(v, precision) << " against "
                    << reference(v, precision);
  }
  EXPECT_EQ(mismatches, 0);
}

// Random bit patterns: subnormals, huge values, every exponent.
TEST(DecimalFormat, EqualsToCharsOnRandomBitPatterns) {
  std::mt19937_64 rng(11);
  int mismatches = 0;
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isnan(v)) continue;  // NaN's text depends on its payload's sign only
    for (const int precision : {9, 12, 15})
      if (formatted(v, precision) != reference(v, precision) && ++mismatches < 10)
        ADD_FAILURE() << v << " at " << precision;
  }
  EXPECT_EQ(mismatches, 0);
}

// The values the fast path must hand over or get exactly right: ties (exact in binary, a 5 just
// past the last digit), values next to powers of ten (the exponent estimate's edge), carries
// that add a digit (9.999999996 -> 10), the ends of fixed notation, zeros and non-finite values.
TEST(DecimalFormat, EqualsToCharsOnTiesPowersOfTenAndCarries) {
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                0.5,
                                123456789.5,
                                1.0000000005,
                                2.25,
                                0.125,
                                9.999999996,
                                99999999.95,
                                9.9999999995e-5,
                                1e-4,
                                1e-5,
                                0.0001,
                                999999999.0,
                                1e9,
                                1e15,
                                0.1,
                                0.3,
                                1.0 / 3,
                                INFINITY,
                                -INFINITY,
                                NAN};
  for (int k = -7; k <= 17; ++k) {
    const double p = std::pow(10.0, k);
    values.push_back(p);
    values.push_back(std::nextafter(p, 0.0));
    values.push_back(std::nextafter(p, INFINITY));
    // Halves at the 9th significant digit, exact in binary when k is small.
    values.push_back(p * (1 + 5e-9));
  }
  for (int n = 1; n < 4096; ++n) values.push_back(n / 4096.0);  // dyadic: exact ties abound
  for (const double v : values)
    for (int precision = 0; precision <= 18; ++precision)
      EXPECT_EQ(formatted(v, precision), reference(v, precision)) << v << " at " << precision;
}

}  // namespace
}  // namespace mq
