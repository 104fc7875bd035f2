// Purpose: test-only checks every statistical convert.* plugin must pass: pass-through, sensor offset, range rate, bad data, small-error limit.
#pragma once

#include "converter_test_support.hpp"

#include <trackflow/error.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <limits>
#include <string>

namespace trackflow::test {

inline void check_pass_through(const std::string& type) {
  auto conv = make(type);
  OneShot out;
  Measurement cart = spherical_measurement(1000, 0.1, 0.2, Vec3(5, 1e-3, 1e-3), AzimuthConvention::NorthClockwise);
  cart.frame = Frame::Cartesian;
  cart.value << 10.0, 20.0, 30.0;
  Measurement got = out.convert(*conv, cart);
  REQUIRE(out.count == 1);
  CHECK(got.frame == Frame::Cartesian);
  CHECK(got.value == cart.value);
  CHECK(got.covariance == cart.covariance);

  Measurement invalid = spherical_measurement(1000, 0.1, 0.2, Vec3(5, 1e-3, 1e-3), AzimuthConvention::NorthClockwise);
  invalid.valid = false;
  invalid.value(0) = std::numeric_limits<double>::quiet_NaN();  // an unlocked radar's garbage is not converted
  got = out.convert(*conv, invalid);
  REQUIRE(out.count == 1);
  CHECK(got.frame == Frame::Spherical);
  CHECK_FALSE(got.valid);
  CHECK(std::isnan(got.value(0)));
}

inline void check_bad_data(const std::string& type) {
  auto conv = make(type, "{}", "conv7");
  OneShot out;
  const Measurement good = spherical_measurement(1000, 0.1, 0.2, Vec3(5, 1e-3, 1e-3), AzimuthConvention::NorthClockwise);
  Measurement bad = good;
  bad.has_range_rate = true;  // says 4 values, has 3
  CHECK_THROWS_WITH(out.convert(*conv, bad), Catch::Contains("node 'conv7'") && Catch::Contains("expected 4"));
  bad = good;
  bad.value(2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(out.convert(*conv, bad), DataError);
  bad = good;
  bad.covariance(1, 1) = -1e-6;
  CHECK_THROWS_WITH(out.convert(*conv, bad), Catch::Contains("negative variance"));
  CHECK(out.count == 0);
}

// With tiny errors every conversion tends to the classical one: position p(m) + sensor,
// covariance J R Jᵀ and range-rate cross-covariance J Cov[(r, az, el), ρ], J numerical.
inline void check_small_error_limit(const std::string& type) {
  auto conv = make(type);
  OneShot out;
  const Vec3 sensor(250.0, -40.0, 12.0);
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const Vec3 s(30e3, -2.2, 0.3);
    const Vec3 sig(2.0, 1e-6, 2e-6);
    const Vec3 cross(0.3 * 2.0 * 0.5, 0.2 * 1e-6 * 0.5, 0.0);  // correlations 0.3 (r), 0.2 (az) with σρ = 0.5
    const Measurement m = spherical_measurement(s(0), s(1), s(2), sig, c, sensor, -80.0, 0.25, cross);
    const Measurement got = out.convert(*conv, m);
    const Mat3 J = numerical_jacobian(s, c);
    const Mat3 R = sig.cwiseProduct(sig).asDiagonal();
    CHECK((got.value.head<3>() - (enu_of(s, c) + sensor)).norm() < 1e-6);
    CHECK(relative_difference(Mat3(got.covariance.topLeftCorner<3, 3>()), Mat3(J * R * J.transpose())) < 1e-6);
    CHECK(relative_difference(Vec3(got.covariance.block<3, 1>(0, 3)), Vec3(J * cross)) < 1e-6);
    CHECK(got.value(3) == -80.0);
    CHECK(got.covariance(3, 3) == 0.25);
    CHECK(got.covariance == got.covariance.transpose());
    CHECK(got.frame == Frame::Cartesian);
    CHECK(got.has_range_rate);
  }
}

// North-clockwise azimuth a and x-counterclockwise azimuth π/2 - a point the same way, so the
// converted positions and covariances must coincide.
inline void check_convention_equivalence(const std::string& type) {
  auto conv = make(type);
  OneShot out;
  const double pi = 3.14159265358979323846;
  for (double az : {0.3, 2.0, -2.7}) {
    const Vec3 sig(20.0, 0.05, 0.03);
    const Measurement nc = spherical_measurement(8e3, az, 0.5, sig, AzimuthConvention::NorthClockwise);
    const Measurement xcc = spherical_measurement(8e3, pi / 2 - az, 0.5, sig, AzimuthConvention::XCounterClockwise);
    const Measurement a = out.convert(*conv, nc);
    const Measurement b = out.convert(*conv, xcc);
    CHECK((a.value - b.value).norm() < 1e-9 * 8e3);
    CHECK(relative_difference(a.covariance, b.covariance) < 1e-12);
  }
}

}  // namespace trackflow::test
