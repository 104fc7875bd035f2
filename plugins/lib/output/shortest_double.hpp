// Purpose: the shortest round-trip text of a double, byte-identical to std::to_chars(first, last, v) (libstdc++'s plain shortest form) and faster (docs/performance.md, "sink.csv: 1 M rows/s"): digits from {fmt}'s Dragonbox, layout here.
#pragma once

// {fmt} (Debian libfmt-dev) is used header-only (the tf_lib_output target defines FMT_HEADER_ONLY):
// only fmt::detail::dragonbox::to_decimal, the significand and decimal exponent of the shortest
// decimal that reads back as the same double (closest of the shortest, ties to even: what
// libstdc++'s Ryu gives). fmt's own layout is not used: it writes 1.2345678901234568e+17 where
// std::to_chars writes 123456789012345680.
#include <fmt/format.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace trackflow::output {

// Room write_shortest needs at `first`: the text is at most 24 characters
// ("-1.2345678901234567e-308"), and the digits go out as whole words, which may write up to 24
// characters past `first` (left for the next text to overwrite).
inline constexpr std::size_t kShortestRoom = 32;

namespace shortest_detail {

inline constexpr char kPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

inline constexpr std::uint64_t kPow10[] = {1ull,
                                           10ull,
                                           100ull,
                                           1000ull,
                                           10000ull,
                                           100000ull,
                                           1000000ull,
                                           10000000ull,
                                           100000000ull,
                                           1000000000ull,
                                           10000000000ull,
                                           100000000000ull,
                                           1000000000000ull,
                                           10000000000000ull,
                                           100000000000000ull,
                                           1000000000000000ull,
                                           10000000000000000ull,
                                           100000000000000000ull,
                                           1000000000000000000ull,
                                           10000000000000000000ull};

inline void put2(char* p, std::uint32_t x) { std::memcpy(p, kPairs + 2 * x, 2); }

// The 8 digits of x < 10^8 (leading zeros kept) as 8 characters in one word, the first digit in
// the lowest byte (the order a little-endian store writes them): two 4-digit halves, each split
// into 2-digit and then 1-digit lanes with multiplications (SWAR).
inline std::uint64_t digits8(std::uint32_t x) {
  const std::uint64_t hi = x / 10000, lo = x % 10000;
  std::uint64_t m = hi | (lo << 32);
  const std::uint64_t q2 = ((m * 10486) >> 20) & 0x0000007F0000007Full;  // lane / 100
  m = q2 | ((m - q2 * 100) << 16);
  const std::uint64_t q1 = ((m * 103) >> 10) & 0x000F000F000F000Full;  // lane / 10
  m = q1 | ((m - q1 * 10) << 8);
  return m | 0x3030303030303030ull;
}

inline void store8(char* p, std::uint64_t w) {
  static_assert(std::endian::native == std::endian::little);
  std::memcpy(p, &w, 8);
}

// Decimal digits of s >= 1.
inline int digit_count(std::uint64_t s) {
  const int t = (static_cast<int>(std::bit_width(s)) * 1233) >> 12;  // floor(log10(2) * bit width): the count or one less
  return t + 1 - (s < kPow10[t]);
}

// The exact decimal integer of a double that is an integer of 16 to 23 digits (the fixed form of
// a shortest text with a non-negative decimal exponent that does not fit the 53-bit
// significand): what std::to_chars writes for it ("as if by printf", %.0f), not the shortest
// digits padded with zeros.
inline char* put_exact_integer(char* out, std::uint64_t bits) {
  const std::uint64_t m = (bits & ((std::uint64_t{1} << 52) - 1)) | (std::uint64_t{1} << 52);
  const int e2 = static_cast<int>((bits >> 52) & 0x7ff) - 1075;
  unsigned __int128 x = e2 >= 0 ? static_cast<unsigned __int128>(m) << e2 : m >> -e2;
  char buf[40];
  char* p = buf + sizeof buf;
  do {
    const auto r = static_cast<std::uint32_t>(x % 100);
    x /= 100;
    p -= 2;
    put2(p, r);
  } while (x != 0);
  if (*p == '0') ++p;  // an odd digit count: the leading pair's zero
  const auto n = static_cast<std::size_t>(buf + sizeof buf - p);
  std::memcpy(out, p, n);
  return out + n;
}

}  // namespace shortest_detail

// Writes what std::to_chars(first, first + kShortestRoom, v) writes (the plain shortest form:
// fixed unless scientific is shorter, printf's exponent spelling, "-0", "inf", "-inf", "nan",
// "-nan") and returns the end of the text. Needs kShortestRoom characters of room at `first`.
inline char* write_shortest(char* first, double v) noexcept {
  using namespace shortest_detail;
  const auto bits = std::bit_cast<std::uint64_t>(v);
  char* out = first;
  if (bits >> 63) *out++ = '-';
  const std::uint64_t magnitude = bits & ~(std::uint64_t{1} << 63);
  if (magnitude >= 0x7ff0000000000000ull) {  // inf or nan (any payload)
    std::memcpy(out, magnitude == 0x7ff0000000000000ull ? "inf" : "nan", 3);
    return out + 3;
  }
  if (magnitude == 0) {
    *out = '0';
    return out + 1;
  }
  // A whole number below 2^53 that does not end in five zeros is its own shortest text (no
  // shorter decimal lies within half a unit of it) in fixed form (four trailing zeros at most):
  // its digits, without the shortest-digit search (truth positions, velocities, counts).
  const int shift = 1075 - static_cast<int>(magnitude >> 52);  // |v| = m / 2^shift
  const std::uint64_t m = (magnitude & ((std::uint64_t{1} << 52) - 1)) | (std::uint64_t{1} << 52);
  std::uint64_t s;
  int e;  // |v| = s * 10^e
  if (static_cast<unsigned>(shift) <= 52 && (m & ((std::uint64_t{1} << shift) - 1)) == 0 &&
      (m >> shift) % 100000 != 0) {
    s = m >> shift;
    e = 0;
  } else {
    const auto dec = fmt::detail::dragonbox::to_decimal(std::bit_cast<double>(magnitude));
    s = dec.significand;
    e = dec.exponent;
  }
  const int len = digit_count(s);

  // The digits padded with zeros to 17 (s * 10^(17 - len) < 10^17), held in registers, not in a
  // buffer read back in other sizes (a store-to-load forwarding stall): the first digit d0, then
  // digits 1-8 in w1 and 9-16 in w2, first digit in the lowest byte.
  const std::uint64_t padded = s * kPow10[17 - len];
  const std::uint64_t top = padded / 10000000000000000ull;
  const std::uint64_t rest = padded - top * 10000000000000000ull;
  const std::uint64_t upper = rest / 100000000;
  const char d0 = static_cast<char>('0' + top);
  const std::uint64_t w1 = digits8(static_cast<std::uint32_t>(upper));
  const std::uint64_t w2 = digits8(static_cast<std::uint32_t>(rest - upper * 100000000));

  // libstdc++'s choice (floating_to_chars.cc, plain form): fixed when it is no longer than
  // scientific, i.e. for -(len + 3) <= e <= 5, tightened by one each side for one digit (no
  // decimal point in its scientific form).
  const int lower = len == 1 ? -3 : -(len + 3);
  const int upper_e = len == 1 ? 4 : 5;
  if (e > upper_e || e < lower) {
    const int sci = e + len - 1;
    out[0] = d0;
    if (len > 1) {
      out[1] = '.';
      store8(out + 2, w1);
      store8(out + 10, w2);
      out += len + 1;
    } else {
      out += 1;
    }
    out[0] = 'e';
    out[1] = sci < 0 ? '-' : '+';
    const auto a = static_cast<std::uint32_t>(sci < 0 ? -sci : sci);
    if (a < 100) {
      put2(out + 2, a);
      return out + 4;
    }
    out[2] = static_cast<char>('0' + a / 100);
    put2(out + 3, a % 100);
    return out + 5;
  }
  if (e >= 0) {
    // A whole number. Below 10^15 (inside the 53-bit significand) the digits and e zeros (the
    // padding) are the value exactly; above, the double's exact integer, as std::to_chars prints it.
    if (len + e <= 15) {
      out[0] = d0;
      store8(out + 1, w1);
      store8(out + 9, w2);
      return out + len + e;
    }
    return put_exact_integer(out, magnitude);
  }
  if (len <= -e) {  // below 1: "0." and up to 3 zeros before the digits
    std::memcpy(out, "0.000000", 8);
    char* const at = out + 2 + (-e - len);
    at[0] = d0;
    store8(at + 1, w1);
    store8(at + 9, w2);
    return at + len;
  }
  // The point inside the digits: after d0 and `k` = len + e - 1 (0..15) more. The 16 digits
  // after d0 become 17 characters, the point at k, merged in registers: bytes below k from the
  // digits, byte k the point, bytes above k the digits moved up by one.
  const int k = len + e - 1;
  std::uint64_t p0, p1;
  if (k < 8) {
    const std::uint64_t below = (std::uint64_t{1} << (8 * k)) - 1;
    const std::uint64_t above = k == 7 ? 0 : ~std::uint64_t{0} << (8 * k + 8);
    p0 = (w1 & below) | (std::uint64_t{'.'} << (8 * k)) | ((w1 << 8) & above);
    p1 = (w2 << 8) | (w1 >> 56);
  } else {
    const int j = k - 8;
    const std::uint64_t below = (std::uint64_t{1} << (8 * j)) - 1;
    const std::uint64_t above = j == 7 ? 0 : ~std::uint64_t{0} << (8 * j + 8);
    p0 = w1;
    p1 = (w2 & below) | (std::uint64_t{'.'} << (8 * j)) | ((w2 << 8) & above);
  }
  out[0] = d0;
  store8(out + 1, p0);
  store8(out + 9, p1);
  out[17] = static_cast<char>(w2 >> 56);
  return out + len + 1;
}

}  // namespace trackflow::output
