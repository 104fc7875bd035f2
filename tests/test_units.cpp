// Purpose: tests of quantity parsing (units, dimensions, errors).
#include <trackflow/units.hpp>

#include <catch2/catch.hpp>

#include <numbers>
#include <stdexcept>

using namespace trackflow;

TEST_CASE("quantities convert to SI with their dimension") {
  CHECK(parse_quantity("3 mrad").value == Approx(3e-3));
  CHECK(parse_quantity("3 mrad").dimension == dim::angle);
  CHECK(parse_quantity("0.2 deg").value == Approx(0.2 * std::numbers::pi / 180));
  CHECK(parse_quantity("1.5 km").value == Approx(1500));
  CHECK(parse_quantity("40 Hz").dimension == dim::frequency);
  CHECK(parse_quantity("25 ms").value == Approx(0.025));
  CHECK(parse_quantity("1.0 m2/s3").dimension == dim::accel_psd);
  CHECK(parse_quantity("1.0 m^2/s^3").dimension == dim::accel_psd);
  CHECK(parse_quantity("200 m/s").dimension == dim::velocity);
  CHECK(parse_quantity("9.81 m/s2").dimension == dim::acceleration);
  CHECK(parse_quantity("10 deg/s").value == Approx(10 * std::numbers::pi / 180));
  CHECK(parse_quantity("100 cm2").value == Approx(0.01));
  CHECK(parse_quantity("-4e3").value == -4000);
  CHECK_FALSE(parse_quantity("-4e3").had_unit);
  CHECK(parse_quantity("50 urad").value == Approx(50e-6));
  CHECK(parse_quantity("50 µrad").value == Approx(50e-6));
}

TEST_CASE("bad quantities are rejected with a reason") {
  CHECK_THROWS_AS(parse_quantity("abc"), std::invalid_argument);
  CHECK_THROWS_AS(parse_quantity("3 furlongs"), std::invalid_argument);
  CHECK_THROWS_AS(parse_quantity(""), std::invalid_argument);
  CHECK_THROWS_AS(parse_quantity("nan"), std::invalid_argument);
  CHECK_THROWS_AS(parse_quantity("inf"), std::invalid_argument);
  CHECK_THROWS_WITH(parse_quantity("3 furlongs"), Catch::Contains("unknown unit"));
}

TEST_CASE("dimensions print in canonical SI") {
  CHECK(dim::accel_psd.str() == "m2/s3");
  CHECK(dim::angle.str() == "rad");
  CHECK(dim::frequency.str() == "1/s");
  CHECK(dim::none.str() == "1");
}
