// Purpose: tests that output::write_shortest (shortest_double.hpp) writes byte for byte what std::to_chars' plain shortest form writes, for every kind of double, and never writes past its room.
#include "output/shortest_double.hpp"

#include <catch2/catch.hpp>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace out = trackflow::output;

namespace {

// Compares write_shortest with std::to_chars for `v`; counts the values and the mismatches, and
// keeps the first few for the report. The buffer's bytes past the room are a sentinel that
// write_shortest must leave alone.
struct Comparison {
  std::uint64_t values = 0;
  std::uint64_t mismatches = 0;
  std::uint64_t overruns = 0;
  std::string first;

  void operator()(double v) {
    ++values;
    char expected[64];
    const auto r = std::to_chars(expected, expected + sizeof expected, v);
    char buf[out::kShortestRoom + 16];
    std::memset(buf, '#', sizeof buf);
    char* const end = out::write_shortest(buf, v);
    const auto n = static_cast<std::size_t>(end - buf);
    const auto m = static_cast<std::size_t>(r.ptr - expected);
    for (std::size_t i = out::kShortestRoom; i < sizeof buf; ++i)
      if (buf[i] != '#') {
        ++overruns;
        break;
      }
    if (n != m || std::memcmp(buf, expected, m) != 0) {
      if (mismatches++ < 8) {
        char line[160];
        std::snprintf(line, sizeof line, "bits 0x%016llx: to_chars '%.*s', write_shortest '%.*s'\n",
                      static_cast<unsigned long long>(std::bit_cast<std::uint64_t>(v)), static_cast<int>(m), expected,
                      static_cast<int>(n > 40 ? 40 : n), buf);
        first += line;
      }
    }
  }
  // v and -v with the doubles on either side.
  void with_neighbours(double v) {
    for (double s : {v, -v}) {
      (*this)(s);
      (*this)(std::nextafter(s, -std::numeric_limits<double>::infinity()));
      (*this)(std::nextafter(s, std::numeric_limits<double>::infinity()));
    }
  }
  void require_identical() const {
    INFO(values << " values compared; first mismatches:\n" << first);
    CHECK(overruns == 0);
    REQUIRE(mismatches == 0);
  }
};

double from_bits(std::uint64_t b) { return std::bit_cast<double>(b); }

}  // namespace

TEST_CASE("number_text: write_shortest is to_chars: 16 M random bits") {
  // Uniform 64-bit patterns: both signs, every binary exponent about equally (subnormals, the
  // largest, NaN payloads and infinities included).
  Comparison cmp;
  std::mt19937_64 rng(20);
  for (int i = 0; i < 16'000'000; ++i) cmp(from_bits(rng()));
  cmp.require_identical();
}

TEST_CASE("number_text: write_shortest is to_chars: subnormals and limits") {
  Comparison cmp;
  std::mt19937_64 rng(21);
  // Random subnormals (no exponent bits), and the smallest and largest ones one by one.
  for (int i = 0; i < 2'000'000; ++i) cmp(from_bits(rng() & 0x800fffffffffffffull));
  for (std::uint64_t m = 1; m <= 100'000; ++m) {
    cmp(from_bits(m));
    cmp(from_bits(0x000fffffffffffffull - m + 1));
  }
  for (double v : {0.0, -0.0, std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::epsilon(), 1.0, 0.1, 0.5})
    cmp.with_neighbours(v);
  for (double v : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::signaling_NaN(), from_bits(0x7ff0000000000001ull),
                   from_bits(0xfff8000000000001ull)})
    cmp(v);
  cmp.require_identical();
}

TEST_CASE("number_text: write_shortest is to_chars: powers of ten and two") {
  Comparison cmp;
  // Every power of ten a double can come near (1e-324 is below the smallest subnormal: 0), with
  // the doubles on both sides, and the doubles nearest the powers computed by the parser.
  for (int k = -324; k <= 308; ++k) {
    const std::string text = "1e" + std::to_string(k);
    double p = 0;
    std::from_chars(text.data(), text.data() + text.size(), p);
    cmp.with_neighbours(p);
    cmp.with_neighbours(std::pow(10.0, k));
    for (int d = 2; d <= 9; ++d) cmp.with_neighbours(d * p);
  }
  // Every power of two (the significand 0: Dragonbox's shorter interval), both neighbours.
  for (int e = 1; e < 2047; ++e) cmp.with_neighbours(from_bits(static_cast<std::uint64_t>(e) << 52));
  cmp.require_identical();
}

TEST_CASE("number_text: write_shortest is to_chars: integers 1e14 to 1e23") {
  // Whole numbers: below 10^15 the shortest digits padded with zeros, above it the double's exact
  // integer (the fixed form std::to_chars chooses up to 22 digits), and where it turns scientific.
  Comparison cmp;
  std::mt19937_64 rng(22);
  for (int k = 14; k <= 23; ++k) {
    const double p = std::pow(10.0, k);
    for (int d = -2000; d <= 2000; ++d) cmp.with_neighbours(p + d * std::max(1.0, std::ldexp(1.0, std::ilogb(p) - 52)));
  }
  // Random integers of 15 to 23 digits, and random integers times powers of ten.
  std::uniform_real_distribution<double> exponent(14.5, 23.5);
  for (int i = 0; i < 2'000'000; ++i) cmp(std::round(std::pow(10.0, exponent(rng))));
  for (int i = 0; i < 1'000'000; ++i) cmp(static_cast<double>(rng() >> (rng() % 40)));
  for (int i = 0; i < 1'000'000; ++i) cmp(static_cast<double>(rng() % 100000) * std::pow(10.0, static_cast<int>(rng() % 24)));
  cmp.require_identical();
}

TEST_CASE("number_text: write_shortest is to_chars: short decimals") {
  // Where fixed and scientific trade places: 1 to 17 significant digits at every decimal
  // exponent -30..30 (0.0001234, 1e-05, 123456, 1.5e+22 ...), log-uniform values over the whole
  // range, and tracking-sized numbers (positions, velocities, sigmas, NIS).
  Comparison cmp;
  std::mt19937_64 rng(23);
  for (int digits = 1; digits <= 17; ++digits)
    for (int e = -30; e <= 30; ++e)
      for (int i = 0; i < 200; ++i) {
        const std::uint64_t lo = digits == 1 ? 1 : static_cast<std::uint64_t>(std::pow(10.0, digits - 1));
        const std::uint64_t mantissa = lo + rng() % (lo * 9);
        const std::string text = std::to_string(mantissa) + "e" + std::to_string(e - digits + 1);
        double v = 0;
        std::from_chars(text.data(), text.data() + text.size(), v);
        cmp.with_neighbours(v);
      }
  std::uniform_real_distribution<double> log10(-310.0, 309.0);
  for (int i = 0; i < 2'000'000; ++i) cmp(std::pow(10.0, log10(rng)));
  std::normal_distribution<double> normal;
  for (int i = 0; i < 2'000'000; ++i) {
    cmp(6000.0 + 3000.0 * normal(rng));
    cmp(150.0 * normal(rng));
    cmp(std::abs(2.0 * normal(rng)));
    cmp(0.1 * static_cast<double>(i % 10000));
  }
  cmp.require_identical();
}
