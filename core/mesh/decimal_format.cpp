#include "core/mesh/decimal_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace mq {

namespace {

// 10^k for k in [0, 22]: every one exact in a double.
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// "00" to "99": two digits at a time.
constexpr char kPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

char* exact(char* out, double v, int precision) {
  return std::to_chars(out, out + 32, v, std::chars_format::general, precision).ptr;
}

}  // namespace

char* format_decimal(char* out, double v, int precision) {
  if (precision <= 0) return std::to_chars(out, out + 32, v).ptr;
  precision = std::min(precision, 17);
  // Past 15 digits the product's rounding error comes near a unit of the last digit kept.
  if (precision > 15 || !std::isfinite(v) || v == 0) return exact(out, v, precision);
  const double a = std::abs(v);
  // e: the decimal exponent of a (10^e <= a < 10^(e + 1)), estimated from the binary one
  // b (2^b <= a < 2^(b + 1)) as floor(b log10 2) = (b * 78913) >> 18 (exact for |b| < 2^11),
  // which is e or e - 1. A subnormal's b is off, but it is far outside the fast path's range.
  std::uint64_t bits;
  std::memcpy(&bits, &a, sizeof bits);
  const int b = static_cast<int>(bits >> 52) - 1023;
  int e = (b * 78913) >> 18;
  // General format is fixed for exponents in [-4, precision); only those take the fast path.
  if (e < -5 || e > precision) return exact(out, v, precision);
  // Near a power of ten the product below may round up to 1; e is then one too large, which
  // gives the same digits (a rounds to 10^e at any precision up to 15).
  if (e + 1 <= 0 ? a * kPow10[-(e + 1)] >= 1 : a >= kPow10[e + 1]) ++e;
  if (e < -4 || e >= precision) return exact(out, v, precision);
  const int shift = precision - 1 - e;  // in [0, precision + 3]: 10^shift is exact
  const double scaled = a * kPow10[shift];
  const auto whole = static_cast<std::uint64_t>(scaled);  // scaled >= 0: truncation is floor
  const double fraction = scaled - static_cast<double>(whole);
  // The product is within half an ulp of a * 10^shift < 10^precision: far from a half by more
  // than that, its nearest integer is the exact rounding (ties go to to_chars too).
  const double margin = kPow10[precision] * 2.3e-16;
  if (std::abs(fraction - 0.5) <= margin) return exact(out, v, precision);
  std::uint64_t m = whole + (fraction > 0.5 ? 1 : 0);
  if (m >= static_cast<std::uint64_t>(kPow10[precision])) return exact(out, v, precision);
  // The digits of m, precision of them (m >= 10^(precision - 1) since a >= 10^e).
  char digits[24];
  int left = precision;  // digits not yet written, from the right
  for (; left >= 2; left -= 2) {
    std::memcpy(digits + left - 2, kPairs + 2 * (m % 100), 2);
    m /= 100;
  }
  if (left == 1) digits[0] = static_cast<char>('0' + m);
  int last = precision;  // one past the last digit kept: trailing zeros after the point go
  const int integer_digits = e >= 0 ? e + 1 : 0;
  while (last > integer_digits && digits[last - 1] == '0') --last;
  char* p = out;
  if (v < 0) *p++ = '-';
  if (e >= 0) {
    for (int i = 0; i < integer_digits; ++i) *p++ = digits[i];
    if (last > integer_digits) {
      *p++ = '.';
      for (int i = integer_digits; i < last; ++i) *p++ = digits[i];
    }
  } else {
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -e - 1; ++i) *p++ = '0';
    for (int i = 0; i < last; ++i) *p++ = digits[i];
  }
  return p;
}

}  // namespace mq
