// Purpose: tests that trackflow/number_range.hpp tells an overflow from an underflow for every text std::from_chars refuses as out of range, and that the quantity parser says which it is.
#include <trackflow/number_range.hpp>
#include <trackflow/units.hpp>

#include <catch2/catch.hpp>

#include <charconv>
#include <string>
#include <system_error>

namespace nr = trackflow::number_range;

namespace {
// What from_chars says of the text (the cases must really be out of range for it).
bool out_of_range(const std::string& s) {
  double v = 0.0;
  return std::from_chars(s.data(), s.data() + s.size(), v).ec == std::errc::result_out_of_range;
}
}  // namespace

TEST_CASE("number_range: refused large numbers are overflows") {
  for (const std::string s : {"1e999", "-1e999", "1.5e309", "179769313486231580793728971405303415079934132710037826936173778980444968292764750946649017977587207096330286416692887910946555547851940402630657488671505820681908902000708383676273854845817711531764475730270069855571366959622842914819860834936475292719074168444365510704342711559699508093042880177904174497792", "0.0001e313", "000000001e309", "1e+400"}) {
    INFO(s);
    REQUIRE(out_of_range(s));
    CHECK(nr::classify(s) == nr::OutOfRange::Overflow);
  }
}

TEST_CASE("number_range: refused small numbers are underflows") {
  std::string zeros = "0.";
  zeros += std::string(400, '0');
  zeros += "1";
  for (const std::string s : {std::string("1e-400"), std::string("-1e-400"), std::string("2e-324"), std::string("0.001e-322"),
                              std::string("1000e-330"), zeros, std::string("1e-999999999999999999999")}) {
    INFO(s);
    REQUIRE(out_of_range(s));
    CHECK(nr::classify(s) == nr::OutOfRange::Underflow);
  }
}

TEST_CASE("number_range: parse_quantity names the end of the range") {
  auto message = [](const char* text) {
    try {
      trackflow::parse_quantity(text);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(message("1e-400 s"), Catch::Matchers::Contains("'1e-400 s' is too small for a double"));
  CHECK_THAT(message("1e999"), Catch::Matchers::Contains("'1e999' is too large for a double"));
  CHECK_THAT(message("fast"), Catch::Matchers::Contains("'fast' is not a number"));
  CHECK(message("4.9e-324") == "accepted");  // the smallest subnormal is a number
}
