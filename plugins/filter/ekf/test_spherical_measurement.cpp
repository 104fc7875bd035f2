// Purpose: tests of spherical_measurement.hpp: h(x) against geometry.hpp, the analytic Jacobian against a numerical one, residual wrapping, singular points.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <catch2/catch.hpp>

#include <numbers>

using namespace trackflow;

namespace {

constexpr AzimuthConvention kConventions[] = {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise};

// Central differences of h over [position, velocity], step scaled to the geometry.
template <int M>
SphericalJacobian<M> numerical_jacobian(const Vec3& d, const Vec3& v, AzimuthConvention c) {
  SphericalJacobian<M> J;
  Vec6 s;
  s << d, v;
  for (int k = 0; k < 6; ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(s(k)));
    Vec6 sp = s, sm = s;
    sp(k) += h;
    sm(k) -= h;
    const SphericalVec<M> hp = spherical_measurement<M>(sp.head<3>(), sp.tail<3>(), c);
    const SphericalVec<M> hm = spherical_measurement<M>(sm.head<3>(), sm.tail<3>(), c);
    J.col(k) = spherical_residual<M>(hp, hm) / (2 * h);  // residual: no 2 pi jump across the branch cut
  }
  return J;
}

// Geometries: ordinary, all octants, low elevation, high elevation, near the branch cut of
// either convention, short range.
std::vector<std::pair<Vec3, Vec3>> geometries() {
  std::vector<std::pair<Vec3, Vec3>> g = {
      {{12e3, 30e3, 4e3}, {-150, 20, 5}},     {{-8e3, -3e3, 500}, {100, -250, -30}},
      {{5e3, -20e3, 10}, {0, 200, 0}},        {{300, 200, 9e3}, {50, -40, 300}},
      {{-1.0, -40e3, 2e3}, {220, 0, 0}},      {{-40e3, 1e-3, 2e3}, {0, 180, 0}},
      {{150, -80, -20}, {-10, 5, 1}},
  };
  Rng rng(11);
  for (int i = 0; i < 20; ++i)
    g.push_back({Vec3(rng.normal(0, 2e4), rng.normal(0, 2e4), std::abs(rng.normal(0, 5e3))),
                 Vec3(rng.normal(0, 200), rng.normal(0, 200), rng.normal(0, 50))});
  return g;
}

}  // namespace

// h(x) agrees with enu_to_spherical and range_rate of geometry.hpp
TEST_CASE("h(x) agrees with enu_to_spherical and range_rate") {
  for (auto c : kConventions)
    for (const auto& [d, v] : geometries()) {
      const auto h = spherical_measurement<4>(d, v, c);
      const Vec3 rae = enu_to_spherical(d, c);
      CHECK(h(0) == Approx(d.norm()).epsilon(1e-14));
      CHECK(h.head<3>() == rae);
      CHECK(h(3) == Approx(range_rate(d, v)).epsilon(1e-12));
      // and it inverts spherical_to_enu
      CHECK((spherical_to_enu(h(0), h(1), h(2), c) - d).norm() < 1e-9 * d.norm());
      const auto h3 = spherical_measurement<3>(d, v, c);
      CHECK(h3 == h.head<3>());
    }
  // Convention check at a known point: due east is 90 deg clockwise from north, 0 deg from x.
  const Vec3 east(1000, 0, 0);
  CHECK(spherical_measurement<3>(east, Vec3::Zero(), AzimuthConvention::NorthClockwise)(1) ==
        Approx(std::numbers::pi / 2));
  CHECK(spherical_measurement<3>(east, Vec3::Zero(), AzimuthConvention::XCounterClockwise)(1) == Approx(0.0));
}

// analytic Jacobian matches a numerical Jacobian, both conventions, with and without range rate
TEST_CASE("analytic Jacobian matches a numerical Jacobian") {
  for (auto c : kConventions)
    for (const auto& [d, v] : geometries()) {
      SphericalJacobian<4> H4;
      SphericalJacobian<3> H3;
      REQUIRE(spherical_measurement_jacobian<4>(d, v, c, H4) == SphericalSingularity::None);
      REQUIRE(spherical_measurement_jacobian<3>(d, v, c, H3) == SphericalSingularity::None);
      const auto N4 = numerical_jacobian<4>(d, v, c);
      const auto N3 = numerical_jacobian<3>(d, v, c);
      // Row by row: entries differ in scale by orders of magnitude (1/r against 1).
      for (int i = 0; i < 4; ++i) {
        INFO("row " << i << " d = " << d.transpose() << " v = " << v.transpose());
        CHECK((H4.row(i) - N4.row(i)).norm() <= 1e-6 * N4.row(i).norm() + 1e-12);
      }
      for (int i = 0; i < 3; ++i) CHECK((H3.row(i) - N3.row(i)).norm() <= 1e-6 * N3.row(i).norm() + 1e-12);
      CHECK(H3 == H4.topRows<3>());
    }
}

// paper 000 eq 3.24 as printed has a wrong rdot/z entry, and the corrected one matches
TEST_CASE("paper 000 eq 3.24 rdot/z entry is corrected") {
  const Vec3 d(3e3, 4e3, 2e3), v(-50, 80, 30);
  const double x = d.x(), y = d.y(), z = d.z(), R = d.norm();
  const double printed = (v.z() * (x * x + y * y) - x * (x * v.x() + y * v.y())) / (R * R * R);
  const double corrected = (v.z() * (x * x + y * y) - z * (x * v.x() + y * v.y())) / (R * R * R);
  const auto N = numerical_jacobian<4>(d, v, AzimuthConvention::XCounterClockwise);
  CHECK(N(3, 2) == Approx(corrected).epsilon(1e-6));
  CHECK(std::abs(N(3, 2) - printed) > 1e-3 * std::abs(N(3, 2)));
}

// residual wraps the azimuth across +-pi and leaves elevation alone
TEST_CASE("residual wraps azimuth but not elevation") {
  SphericalVec<4> z, h;
  z << 1000, std::numbers::pi - 0.01, 0.3, -5;
  h << 990, -std::numbers::pi + 0.01, 0.2, -4;
  const auto nu = spherical_residual<4>(z, h);
  CHECK(nu(0) == Approx(10));
  CHECK(nu(1) == Approx(-0.02));
  CHECK(nu(2) == Approx(0.1));
  CHECK(nu(3) == Approx(-1));
  // elevation is not wrapped: a difference above pi stays as is (cannot happen for valid el,
  // and wrapping it would hide a corrupted value)
  z(2) = 1.5;
  h(2) = -1.5;
  CHECK(spherical_residual<4>(z, h)(2) == Approx(3.0));
}

// at the zenith and at the sensor the Jacobian is finite and flagged
TEST_CASE("Jacobian is finite and flagged at the zenith") {
  for (auto c : kConventions) {
    SphericalJacobian<4> H;
    CHECK(spherical_measurement_jacobian<4>(Vec3(0, 0, 5000), Vec3(100, 0, 10), c, H) == SphericalSingularity::Zenith);
    CHECK(H.allFinite());
    CHECK(H(0, 2) == Approx(1.0));           // dr/dz
    CHECK(H(2, 2) == 0.0);                    // del/dz = rho/r^2 = 0
    CHECK(H.row(1).norm() > 1e3 / 5000.0);    // floored, large azimuth gradient
    CHECK(spherical_measurement_jacobian<4>(Vec3(1e-2, 0, 5000), Vec3::Zero(), c, H) == SphericalSingularity::None);
    CHECK(spherical_measurement_jacobian<4>(Vec3::Zero(), Vec3(1, 2, 3), c, H) == SphericalSingularity::AtSensor);
    CHECK(H.isZero());
    const auto h = spherical_measurement<4>(Vec3::Zero(), Vec3(3, 4, 0), c);
    CHECK(h.allFinite());
  }
}
