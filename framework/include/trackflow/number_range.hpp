// Purpose: why a decimal number that std::from_chars refused as out of range is out of range — too large (overflow) or too small (underflow) — and the words that say so, for every number parser's messages.
#pragma once

#include <cstddef>
#include <string_view>

namespace trackflow::number_range {

enum class OutOfRange { Overflow, Underflow };

// std::from_chars gives errc::result_out_of_range both for 1e999 (beyond DBL_MAX) and for
// 1e-400 (nonzero but below the smallest subnormal, 4.9e-324), without a value; calling both
// "NaN or infinite" (issue 27) or "not a number" misleads. The two differ in the decimal
// exponent of the first significant digit: >= 0 for an overflow, < 0 for an underflow (the
// refused range starts 308 orders away from 1 on either side, so the sign decides). `text` is
// what from_chars matched: an optional sign, digits with an optional point, an optional exponent.
inline OutOfRange classify(std::string_view text) {
  std::size_t i = 0;
  const std::size_t n = text.size();
  auto digit = [&](std::size_t k) { return k < n && text[k] >= '0' && text[k] <= '9'; };
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  long long integer_digits = 0, zeros_after_point = 0;  // significant integer digits; zeros before the first fraction one
  bool significant = false;
  for (; digit(i); ++i)
    if (significant || text[i] != '0') significant = true, ++integer_digits;
  if (i < n && text[i] == '.')
    for (++i; digit(i); ++i)
      if (!significant) {
        if (text[i] == '0')
          ++zeros_after_point;
        else
          significant = true;
      }
  long long exponent = 0;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    const bool negative = i < n && text[i] == '-';
    if (i < n && (text[i] == '-' || text[i] == '+')) ++i;
    for (; digit(i); ++i)
      if (exponent < 1000000000LL) exponent = exponent * 10 + (text[i] - '0');  // saturates: only the sign matters
    if (negative) exponent = -exponent;
  }
  const long long decimal_exponent = integer_digits > 0 ? integer_digits - 1 + exponent : exponent - zeros_after_point - 1;
  return decimal_exponent < 0 ? OutOfRange::Underflow : OutOfRange::Overflow;
}

// The words for a message: "is too large for a double (beyond +-1.8e308)", "is too small for a
// double (nonzero but below 4.9e-324 in magnitude: it underflows; write 0)".
inline const char* describe(OutOfRange r) {
  return r == OutOfRange::Overflow
             ? "is too large for a double (beyond +-1.8e308)"
             : "is too small for a double (nonzero but below 4.9e-324 in magnitude: it underflows; write 0)";
}

}  // namespace trackflow::number_range
