// Doubles as decimal text for the writers (OBJ, PLY, the saved quilt): the bytes of
// std::to_chars(v, chars_format::general, precision), faster where it can be done exactly.
//
// Why: writing the armor's 1.4M vertices spent 42% of its time in libstdc++'s exact
// fixed-precision conversion (issue 27). For a value whose exponent keeps it in fixed notation,
// v times a power of ten that is exact in a double is one rounding away from the true product,
// so its nearest integer is the correctly rounded digit string unless the product lies within
// that rounding of a half; those few (ties included) take std::to_chars.
#pragma once

namespace mq {

// Writes v as std::to_chars(out, out + 32, v, std::chars_format::general, precision) does, or
// as the shortest round-trip form (std::to_chars(out, out + 32, v)) when precision <= 0.
// Precision is clamped to 17 (17 significant digits already round-trip).
//   out  room for at least 32 characters
// Returns one past the last character written. Throws nothing.
char* format_decimal(char* out, double v, int precision);

}  // namespace mq
