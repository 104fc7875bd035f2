// Purpose: tests of the range law R(r) = alpha (r/r0)^a + beta (r0/r)^b of adapt.range_r.
#include "range_law.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using trackflow::adapt::RangeLaw;

TEST_CASE("range law has its closed form") {
  RangeLaw law{400e-12, 900e-12, 100e3};
  CHECK(law.variance(100e3) == Approx(1300e-12).epsilon(1e-14));
  CHECK(law.variance(200e3) == Approx(16 * 400e-12 + 900e-12 / 4).epsilon(1e-14));
  CHECK(law.variance(50e3) == Approx(400e-12 / 16 + 4 * 900e-12).epsilon(1e-14));
  CHECK(law.thermal(200e3) == Approx(6400e-12).epsilon(1e-14));
  CHECK(law.glint(200e3) == Approx(225e-12).epsilon(1e-14));
  // Below min_range the law is held.
  law.min_range = 1e3;
  CHECK(law.variance(10.0) == law.variance(1e3));
}

// dR/dr = 0 at r0 (b beta / (a alpha))^(1/(a+b)): a numerical check that it is the minimum.
TEST_CASE("range law minimum is where its derivative vanishes") {
  const RangeLaw law{400e-12, 900e-12, 100e3};
  const double rm = law.minimum_range();
  CHECK(rm == Approx(100e3 * std::pow(2.0 * 900 / (4.0 * 400), 1.0 / 6)).epsilon(1e-14));
  CHECK(law.variance(rm) < law.variance(rm * 1.001));
  CHECK(law.variance(rm) < law.variance(rm * 0.999));
}

TEST_CASE("zero exponents make R constant") {
  const RangeLaw law{400e-12, 900e-12, 100e3, 0.0, 0.0};
  for (double r : {1e3, 1e5, 3e5}) CHECK(law.variance(r) == Approx(1300e-12).epsilon(1e-14));
}
