// Purpose: tests of convert.clark_elevation: the correction at the measured elevation and solved at the corrected one, the elevation covariance mapped by the correction's derivative, and the behaviour below 2 deg.
#include "physics/refraction.hpp"

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

Measurement spherical(double el, bool valid = true) {
  Measurement m;
  m.frame = Frame::Spherical;
  m.valid = valid;
  m.value = MeasVec::Zero(3);
  m.value << 1.5e6, 2.9, el;
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() << 25.0, 3e-10, 3e-10;
  m.covariance(0, 2) = m.covariance(2, 0) = 1e-6;
  return m;
}

struct Run {
  std::vector<Measurement> out;
  Summary summary;
};

Run convert(const std::string& yaml, const std::vector<Measurement>& in) {
  auto c = test::make("convert.clark_elevation", yaml);
  test::Collector out;
  out.attach_to(*c);
  Diagnostics d;
  c->start_run({0, 1, &d});
  for (const auto& m : in) c->on_measurement(m, 0);
  auto r = c->end_run();
  c->merge(*r);
  Run run;
  c->finish(run.summary, {});
  run.out = std::move(out.measurements);
  return run;
}

}  // namespace

// measured: theta_c = theta_m - b(theta_m) (paper 004's baseline); solved: theta_c + b(theta_c) =
// theta_m to rounding. Range and azimuth pass unchanged; the elevation's variance and covariances
// scale with d theta_c / d theta_m.
TEST_CASE("correction at measured and solved elevation") {
  sim::ClarkModel clark;
  for (double el : {2.5, 5.0, 9.0, 30.0}) {
    INFO("elevation " << el << " deg");
    const Measurement in = spherical(el * kDeg);
    const Measurement a = convert("{}", {in}).out.at(0);
    CHECK(a.value(2) == Approx(el * kDeg - clark.bias(el * kDeg)).epsilon(1e-14));
    CHECK(a.value(0) == in.value(0));
    CHECK(a.value(1) == in.value(1));
    const double g = 1.0 - clark.at(el * kDeg).db;
    CHECK(a.covariance(2, 2) == Approx(g * g * 3e-10).epsilon(1e-12));
    CHECK(a.covariance(0, 2) == Approx(g * 1e-6).epsilon(1e-12));
    CHECK(a.covariance(0, 0) == 25.0);
    const Measurement s = convert("evaluate_at: solved\niterations: 20", {in}).out.at(0);
    CHECK(s.value(2) + clark.bias(s.value(2)) == Approx(el * kDeg).epsilon(1e-14));
    // The measured-point correction leaves b(theta_m) - b(theta) ~ -b' b behind: 0.04 deg at 2.5 deg.
    if (el == 2.5) CHECK((a.value(2) - s.value(2)) / kDeg == Approx(0.034).epsilon(0.15));
  }
}

// Below 2 deg: invalid (counted), hold (b of 2 deg), extrapolate; invalid input passes unchanged.
TEST_CASE("clark correction below 2 deg and invalid input") {
  sim::ClarkModel clark;
  const Run inv = convert("{}", {spherical(1.5 * kDeg), spherical(3 * kDeg, false)});
  REQUIRE(inv.out.size() == 2);
  CHECK_FALSE(inv.out[0].valid);
  CHECK(inv.out[0].value(2) == 1.5 * kDeg);
  CHECK_FALSE(inv.out[1].valid);
  CHECK(inv.out[1].value(2) == 3 * kDeg);
  CHECK(inv.summary.find("invalid_below_2deg")->value == 1);
  CHECK(inv.summary.find("corrected")->value == 0);
  const Measurement hold = convert("clark_below_2deg: hold", {spherical(1.5 * kDeg)}).out.at(0);
  CHECK(hold.valid);
  CHECK(hold.value(2) == Approx(1.5 * kDeg - clark.bias(2 * kDeg)).epsilon(1e-14));
  const Measurement ex = convert("clark_below_2deg: extrapolate", {spherical(1.5 * kDeg)}).out.at(0);
  CHECK(ex.value(2) < hold.value(2));
}

TEST_CASE("clark converter parameters are checked") {
  CHECK_THROWS_WITH(test::make("convert.clark_elevation", "iterations: 3"), Catch::Contains("evaluate_at: solved"));
  CHECK_THROWS_WITH(test::make("convert.clark_elevation", "n0: 2000"), Catch::Contains("n0"));
}
