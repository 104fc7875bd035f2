// Purpose: numbers as output text through std::to_chars: byte-identical to printf's "%.*g" and "%.*f", shortest round-trip, unsigned integers; appended to a string or written into a caller's buffer.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <system_error>

// std::to_chars is specified to give exactly what printf gives for the same format and
// precision (C++17 [charconv.to.chars]: "as if by printf in the C locale"), but without
// printf's format parsing, locale and multi-precision arithmetic: a number costs a quarter to a
// fifth of snprintf's time (docs/performance.md, "Number formatting"). Non-finite values come
// out as printf writes them ("inf", "-inf", "nan", "-nan"); most callers decide themselves what
// a NaN becomes before calling these.
namespace trackflow::number_text {

namespace detail {

// Longest text of the shortest form and of "%.*g" up to 40 digits ("-1.2345678901234567e-308"
// is 24 characters); "%.*f" of a large value or a large precision takes the slow path.
constexpr std::size_t kStackChars = 64;

template <class... Format>
void append(std::string& out, double v, std::size_t worst, Format... format) {
  char buf[kStackChars];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, format...);
  // append(pointer, count), not append(first, last): the iterator overload goes through replace().
  if (r.ec == std::errc()) {
    out.append(buf, static_cast<std::size_t>(r.ptr - buf));
    return;
  }
  std::string big(worst, '\0');
  const auto b = std::to_chars(big.data(), big.data() + big.size(), v, format...);
  out.append(big.data(), static_cast<std::size_t>(b.ptr - big.data()));
}

// Digits before the point of the largest double (309), sign, point, exponent: room for any
// precision-formatted double when the precision is added.
inline std::size_t worst_case(int precision) { return 330 + static_cast<std::size_t>(precision < 0 ? 6 : precision); }

}  // namespace detail

// Room a write_* call below needs at `first`: any shortest text ("-1.2345678901234567e-308" is 24
// characters), any "%.*g" up to precision 17 (sign, 17 digits, point and "e-308", or "0.000"
// before the digits: at most 24), any unsigned 64-bit integer (20 digits). For a writer that
// assembles many numbers in its own buffer (sink.csv's rows): no string growth per number.
inline constexpr std::size_t kWriteRoom = 32;

// The shortest text that reads back as exactly `v` (as append_shortest), written at `first`
// (kWriteRoom characters of room); returns the end of the text.
inline char* write_shortest(char* first, double v) noexcept { return std::to_chars(first, first + kWriteRoom, v).ptr; }

// printf("%.*g", precision, v) for precision <= 17 (as append_general), written at `first`
// (kWriteRoom characters of room); returns the end of the text. Larger precisions: append_general.
inline char* write_general(char* first, double v, int precision) noexcept {
  return std::to_chars(first, first + kWriteRoom, v, std::chars_format::general, precision).ptr;
}

// printf("%llu", v), written at `first` (kWriteRoom characters of room); returns the end.
inline char* write_unsigned(char* first, std::uint64_t v) noexcept { return std::to_chars(first, first + kWriteRoom, v).ptr; }

// printf("%.*g", precision, v), appended.
inline void append_general(std::string& out, double v, int precision) {
  detail::append(out, v, detail::worst_case(precision), std::chars_format::general, precision);
}

// printf("%.*f", precision, v), appended.
inline void append_fixed(std::string& out, double v, int precision) {
  detail::append(out, v, detail::worst_case(precision), std::chars_format::fixed, precision);
}

// The shortest text that reads back (strtod, std::from_chars) as exactly `v`.
inline void append_shortest(std::string& out, double v) { detail::append(out, v, detail::kStackChars); }

// printf("%llu", v), appended.
inline void append_unsigned(std::string& out, std::uint64_t v) {
  char buf[20];  // 2^64 - 1 has 20 digits
  out.append(buf, static_cast<std::size_t>(std::to_chars(buf, buf + sizeof buf, v).ptr - buf));
}

inline std::string general(double v, int precision) {
  std::string s;
  append_general(s, v, precision);
  return s;
}

inline std::string fixed(double v, int precision) {
  std::string s;
  append_fixed(s, v, precision);
  return s;
}

inline std::string shortest(double v) {
  std::string s;
  append_shortest(s, v);
  return s;
}

}  // namespace trackflow::number_text
