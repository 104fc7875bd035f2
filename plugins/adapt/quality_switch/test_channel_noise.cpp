// Purpose: tests of the per-channel q mapping: line-of-sight scaling by hand, the ENU diagonal against a numerically differentiated full J Q J'.
#include "channel_noise.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace trackflow;
using adapt::ChannelPsd;

namespace {

// d(x, y, z)/d(r, az, el) by central differences of spherical_to_enu.
Mat3 numerical_jacobian(double r, double az, double el, AzimuthConvention c) {
  Mat3 J;
  const double h[3] = {1e-3, 1e-7, 1e-7};
  for (int k = 0; k < 3; ++k) {
    Vec3 a(r, az, el), b(r, az, el);
    a(k) += h[k];
    b(k) -= h[k];
    J.col(k) = (spherical_to_enu(a(0), a(1), a(2), c) - spherical_to_enu(b(0), b(1), b(2), c)) / (2 * h[k]);
  }
  return J;
}

}  // namespace

// line-of-sight PSDs: range as is, angles times (r cos el)^2 and r^2
TEST_CASE("line-of-sight PSDs scale angles by range terms") {
  const ChannelPsd q{0.01, 1e-13, 2e-13};
  const double r = 140e3, el = 0.3;
  const Vec3 los = adapt::line_of_sight_psd(q, r, el);
  CHECK(los(0) == 0.01);
  CHECK(los(1) == Approx(std::pow(r * std::cos(el), 2) * 1e-13));
  CHECK(los(2) == Approx(r * r * 2e-13));
}

// ENU-axis PSDs are the diagonal of J diag(q) J' and keep its trace
TEST_CASE("ENU-axis PSDs are diag of J diag(q) J'") {
  const ChannelPsd q{0.03, 4e-13, 1e-13};
  for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (double az : {0.0, 0.7, 2.5, -1.9}) {
      for (double el : {0.0, 0.4, 1.2}) {
        const double r = 120e3;
        const Mat3 J = numerical_jacobian(r, az, el, conv);
        const Mat3 full = J * Vec3(q.range, q.azimuth, q.elevation).asDiagonal() * J.transpose();
        const Vec3 diag = adapt::enu_axis_psd(q, r, az, el, conv);
        INFO("az " << az << " el " << el);
        for (int i = 0; i < 3; ++i) CHECK(diag(i) == Approx(full(i, i)).epsilon(1e-6).margin(1e-12));
        // The trace is the line-of-sight total: a rotation of the line-of-sight PSDs.
        CHECK(diag.sum() == Approx(adapt::line_of_sight_psd(q, r, el).sum()).epsilon(1e-9));
      }
    }
  }
}

// ENU-axis PSDs are exact when the line of sight lies along north
TEST_CASE("ENU-axis PSDs are exact for a northward LOS") {
  // north_clockwise, az = 0, el = 0: range along y, azimuth along x, elevation along z.
  const ChannelPsd q{0.05, 1e-12, 3e-12};
  const double r = 100e3;
  const Vec3 diag = adapt::enu_axis_psd(q, r, 0.0, 0.0, AzimuthConvention::NorthClockwise);
  CHECK(diag(0) == Approx(r * r * 1e-12));
  CHECK(diag(1) == Approx(0.05));
  CHECK(diag(2) == Approx(r * r * 3e-12));
}
