// Purpose: tests of the angle-curvature variance near the zenith against numerical Hessians of geometry.hpp's azimuth and elevation.
#include "estimation/zenith_linearisation.hpp"

#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

using namespace trackflow;

namespace {

// Numerical Hessian of angle `row` (1 az, 2 el) of enu_to_spherical w.r.t. position.
Mat3 hessian(const Vec3& d, int row, AzimuthConvention c, double h) {
  auto f = [&](const Vec3& p) { return enu_to_spherical(p, c)(row); };
  Mat3 A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Vec3 ei = Vec3::Zero(), ej = Vec3::Zero();
      ei(i) = h;
      ej(j) = h;
      A(i, j) = (f(d + ei + ej) - f(d + ei - ej) - f(d - ei + ej) + f(d - ei - ej)) / (4 * h * h);
    }
  return A;
}

}  // namespace

// curvature variances equal 1/2 tr(A P A P) with numerical Hessians near the zenith
TEST_CASE("zenith curvature variances match numerical Hessians") {
  Eigen::Matrix2d Ph;
  Ph << 0.30, 0.05, 0.05, 0.02;  // anisotropic, correlated
  Mat3 P3 = Mat3::Zero();
  P3.topLeftCorner<2, 2>() = Ph;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise})
    for (const Vec3& d : {Vec3(4.0, 3.0, 1500.0), Vec3(-20.0, 7.0, 3000.0), Vec3(0.5, -1.2, 800.0)}) {
      const auto v = ekf::angle_curvature_variance(d, Ph, 1e-9);
      const double rho = std::hypot(d.x(), d.y());
      const Mat3 Aaz = hessian(d, 1, c, 1e-3 * rho), Ael = hessian(d, 2, c, 1e-3 * rho);
      const double var_az = 0.5 * (Aaz * P3 * Aaz * P3).trace(), var_el = 0.5 * (Ael * P3 * Ael * P3).trace();
      INFO("d = " << d.transpose());
      CHECK(v.azimuth == Approx(var_az).epsilon(1e-4));  // the az Hessian is exact
      CHECK(v.elevation == Approx(var_el).epsilon(0.01 + 10 * rho / d.z()));  // dominant term only
      CHECK(v.azimuth_unusable == (rho * rho < 9 * Ph.trace()));
    }
}

// far from the zenith the curvature terms are negligible against radar noise
TEST_CASE("far from the zenith curvature terms are negligible") {
  Eigen::Matrix2d Ph = Eigen::Matrix2d::Identity() * 100.0;  // 10 m per axis at 10 km
  const auto v = ekf::angle_curvature_variance(Vec3(8e3, 6e3, 1e3), Ph, 1e-9);
  CHECK(v.azimuth < 1e-5 * 1e-6);  // below 1e-5 of a (1 mrad)^2 azimuth variance
  CHECK(v.elevation < 1e-5 * 1e-6);
  CHECK_FALSE(v.azimuth_unusable);
}
