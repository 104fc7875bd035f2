// Purpose: tests of convert.classical: position and covariance against a numerical Jacobian, both azimuth conventions.
#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {
Measurement spherical(double r, double az, double el, AzimuthConvention c) {
  Measurement m;
  m.frame = Frame::Spherical;
  m.azimuth = c;
  m.value.resize(3);
  m.value << r, az, el;
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() << 100.0, 1e-6, 4e-6;
  m.sensor_position = Vec3(100, -50, 3);
  return m;
}
}  // namespace

// converted position matches the azimuth convention and adds the sensor position
TEST_CASE("position follows azimuth convention and sensor") {
  auto conv = test::make("convert.classical");
  test::Collector out;
  out.attach_to(*conv);
  conv->on_measurement(spherical(1000, 0.0, 0.0, AzimuthConvention::NorthClockwise), 0);
  conv->on_measurement(spherical(1000, 0.0, 0.0, AzimuthConvention::XCounterClockwise), 0);
  REQUIRE(out.measurements.size() == 2);
  // North-clockwise azimuth 0 points north (+y); x-counterclockwise 0 points east (+x).
  CHECK(out.measurements[0].value(0) == Approx(100));
  CHECK(out.measurements[0].value(1) == Approx(950));
  CHECK(out.measurements[1].value(0) == Approx(1100));
  CHECK(out.measurements[1].value(1) == Approx(-50));
  CHECK(out.measurements[0].frame == Frame::Cartesian);
}

// covariance is J R J' with J equal to a numerical Jacobian
TEST_CASE("covariance is J R J' with a numerical J") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const double r = 25e3, az = 2.3, el = 0.4;
    const Mat3 J = spherical_to_enu_jacobian(r, az, el, c);
    Mat3 Jn;
    const Vec3 x0(r, az, el);
    for (int k = 0; k < 3; ++k) {
      Vec3 h = Vec3::Zero();
      h(k) = k == 0 ? 1e-3 : 1e-7;
      const Vec3 xp = x0 + h, xm = x0 - h;
      Jn.col(k) = (spherical_to_enu(xp(0), xp(1), xp(2), c) - spherical_to_enu(xm(0), xm(1), xm(2), c)) / (2 * h(k));
    }
    CHECK((J - Jn).norm() / J.norm() < 1e-7);

    auto conv = test::make("convert.classical");
    test::Collector out;
    out.attach_to(*conv);
    const Measurement m = spherical(r, az, el, c);
    conv->on_measurement(m, 0);
    const Mat3 expected = Jn * m.covariance.topLeftCorner(3, 3) * Jn.transpose();
    const Mat3 got = out.measurements.at(0).covariance;
    CHECK((got - expected).norm() / expected.norm() < 1e-6);
    CHECK((got - got.transpose()).norm() == 0.0);
  }
}

TEST_CASE("range rate is carried through unchanged") {
  auto conv = test::make("convert.classical");
  test::Collector out;
  out.attach_to(*conv);
  Measurement m = spherical(5000, 0.3, 0.2, AzimuthConvention::NorthClockwise);
  m.has_range_rate = true;
  m.value.conservativeResize(4);
  m.value(3) = -120.0;
  MeasCov c = MeasCov::Zero(4, 4);
  c.topLeftCorner(3, 3) = m.covariance;
  c(3, 3) = 0.25;
  m.covariance = c;
  conv->on_measurement(m, 0);
  REQUIRE(out.measurements.at(0).value.size() == 4);
  CHECK(out.measurements[0].value(3) == -120.0);
  CHECK(out.measurements[0].covariance(3, 3) == Approx(0.25));
}
