// Purpose: tests that trackflow/number_text.hpp writes exactly what snprintf writes ("%.*g", "%.*f", "%llu") and that its shortest form reads back exactly.
#include <trackflow/number_text.hpp>

#include <catch2/catch.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace nt = trackflow::number_text;

namespace {

std::string printf_text(const char* format, int precision, double v) {
  char buf[512];
  std::snprintf(buf, sizeof buf, format, precision, v);
  return buf;
}

double from_bits(std::uint64_t bits) {
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// Values where formatting goes wrong if anything does: every kind of double, from random bit
// patterns (all exponents, subnormals, NaN payloads) to typical tracking magnitudes, exact powers
// of ten, the limits, and decimal halfway points ("…5" at each precision) with their neighbours
// on both sides, where a formatter that rounds in binary instead of exactly is off by one digit.
std::vector<double> awkward_values() {
  std::vector<double> v = {0.0,
                           -0.0,
                           1.0,
                           -1.0,
                           0.1,
                           0.5,
                           1.5,
                           2.5,
                           0.125,
                           0.15,
                           9.5,
                           99.5,
                           999999.5,
                           9999999999.5,
                           0.00001,
                           0.0001,
                           123456.0,
                           1234567.0,
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::lowest(),
                           std::numeric_limits<double>::epsilon(),
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN(),
                           -std::numeric_limits<double>::quiet_NaN()};
  for (int e = -324; e <= 308; ++e) {
    const double p = std::pow(10.0, e);
    v.push_back(p);
    v.push_back(-p);
    v.push_back(std::nextafter(p, 0.0));
    v.push_back(std::nextafter(p, INFINITY));
  }
  std::mt19937_64 gen(20);
  for (int i = 0; i < 20000; ++i) v.push_back(from_bits(gen()));
  for (int i = 0; i < 2000; ++i) v.push_back(from_bits(gen() & 0x000fffffffffffffULL));  // subnormals
  std::normal_distribution<double> metres(0.0, 5000.0);
  for (int i = 0; i < 20000; ++i) v.push_back(metres(gen));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 5000; ++i) v.push_back(std::pow(10.0, 40.0 * unit(gen) - 20.0) * (unit(gen) < 0.5 ? -1 : 1));
  // Halfway cases: d.dd…d5 × 10^k for 1 to 17 significant digits, nearest doubles and their neighbours.
  std::uniform_int_distribution<int> digit(0, 9), exponent(-30, 30);
  for (int digits = 1; digits <= 17; ++digits)
    for (int i = 0; i < 300; ++i) {
      std::string s = std::to_string(1 + digit(gen) % 9) + ".";
      for (int d = 1; d < digits; ++d) s += static_cast<char>('0' + digit(gen));
      s += "5e" + std::to_string(exponent(gen));
      const double h = std::strtod(s.c_str(), nullptr);
      v.push_back(h);
      v.push_back(std::nextafter(h, 0.0));
      v.push_back(std::nextafter(h, INFINITY));
    }
  return v;
}

}  // namespace

TEST_CASE("number_text: general equals snprintf %.*g, all precisions") {
  const auto values = awkward_values();
  long compared = 0;
  for (int precision : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 20, 25, 40, -1})
    for (double v : values) {
      const std::string want = printf_text("%.*g", precision, v);
      const std::string got = nt::general(v, precision);
      if (got != want) FAIL("%." << precision << "g of " << printf_text("%.*a", 13, v) << ": " << got << " vs " << want);
      ++compared;
    }
  CHECK(compared > 1000000);
}

TEST_CASE("number_text: write_* equal the append_* forms") {
  const auto values = awkward_values();
  char buf[nt::kWriteRoom + 8];
  for (double v : values) {
    for (int precision : {0, 1, 6, 10, 12, 15, 16, 17, -1}) {
      std::memset(buf, '#', sizeof buf);
      char* end = nt::write_general(buf, v, precision);
      REQUIRE(end <= buf + nt::kWriteRoom);
      const std::string want = printf_text("%.*g", precision, v);
      if (std::string(buf, end) != want)
        FAIL("write_general %." << precision << "g of " << printf_text("%.*a", 13, v) << ": " << std::string(buf, end));
      CHECK(buf[nt::kWriteRoom] == '#');
    }
    char* end = nt::write_shortest(buf, v);
    REQUIRE(end <= buf + nt::kWriteRoom);
    if (std::string(buf, end) != nt::shortest(v)) FAIL("write_shortest of " << printf_text("%.*a", 13, v));
  }
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  CHECK(std::string(buf, nt::write_unsigned(buf, max)) == "18446744073709551615");
  CHECK(std::string(buf, nt::write_unsigned(buf, 0)) == "0");
}

TEST_CASE("number_text: fixed equals snprintf %.*f, also long texts") {
  const auto values = awkward_values();
  for (int precision : {0, 1, 2, 3, 4, 6, 10, 17, 30})
    for (double v : values) {
      const std::string want = printf_text("%.*f", precision, v);
      const std::string got = nt::fixed(v, precision);
      if (got != want) FAIL("%." << precision << "f of " << printf_text("%.*a", 13, v) << ": " << got << " vs " << want);
    }
  // 1e308 has 309 digits before the point: the long path, still exact.
  CHECK(nt::fixed(1e308, 4) == printf_text("%.*f", 4, 1e308));
  CHECK(nt::fixed(-std::numeric_limits<double>::max(), 2).size() == 313);  // sign, 309 digits, point, 2
}

TEST_CASE("number_text: non-finite values spelt as printf spells them") {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(nt::general(inf, 10) == "inf");
  CHECK(nt::general(-inf, 10) == "-inf");
  CHECK(nt::general(nan, 10) == "nan");
  CHECK(nt::general(-nan, 10) == printf_text("%.*g", 10, -nan));
  CHECK(nt::fixed(-inf, 4) == "-inf");
  CHECK(nt::shortest(inf) == "inf");
  CHECK(nt::shortest(nan) == "nan");
}

TEST_CASE("number_text: shortest round-trips, no longer than %.17g") {
  for (double v : awkward_values()) {
    if (std::isnan(v)) continue;
    const std::string s = nt::shortest(v);
    double back = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), back);
    REQUIRE(r.ec == std::errc());
    REQUIRE(r.ptr == s.data() + s.size());
    if (std::memcmp(&back, &v, sizeof v) != 0) FAIL(s << " reads back as " << printf_text("%.*g", 17, back));
    CHECK(std::strtod(s.c_str(), nullptr) == v);
    CHECK(s.size() <= printf_text("%.*g", 17, v).size());
  }
  CHECK(nt::shortest(0.1) == "0.1");
  CHECK(nt::shortest(-0.0) == "-0");
}

TEST_CASE("number_text: unsigned equals snprintf %llu and appends") {
  std::mt19937_64 gen(7);
  std::vector<std::uint64_t> values = {0, 1, 9, 10, 99, 100, std::numeric_limits<std::uint64_t>::max()};
  for (int i = 0; i < 10000; ++i) values.push_back(gen() >> (i % 64));
  for (std::uint64_t v : values) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(v));
    std::string s = "run ";
    nt::append_unsigned(s, v);
    CHECK(s == std::string("run ") + buf);
  }
}
