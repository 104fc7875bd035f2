// Purpose: the radar measurement model h(x) = [r, az, el(, rdot)] of a Cartesian target, its analytic Jacobian, and the angle-aware residual.
#pragma once

#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace trackflow {

// M = 3: [r, az, el]; M = 4: [r, az, el, rdot] (range rate last, as in Measurement::value).
template <int M>
using SphericalVec = Eigen::Matrix<double, M, 1>;
// d h / d [position(3), velocity(3)]: scatter the columns into any state layout.
template <int M>
using SphericalJacobian = Eigen::Matrix<double, M, 6>;

// Where the angle rows of the Jacobian stop being defined.
enum class SphericalSingularity : std::uint8_t {
  None,
  // Horizontal range below kZenithFraction * r: the azimuth is undefined (its row grows like
  // 1/horizontal range). The row is evaluated at the floored horizontal range so it stays
  // finite, but it must not be trusted; filter.ekf drops the azimuth from that update.
  Zenith,
  // r below kMinRange (target at the sensor): no direction at all; the Jacobian is zero.
  AtSensor,
};
inline constexpr double kZenithFraction = 1e-6;
inline constexpr double kMinRange = 1e-6;  // m

// h for a target at d = position - sensor position with velocity v (sensor at rest), in the
// sensor's azimuth convention. Same conventions as enu_to_spherical / range_rate (geometry.hpp),
// so at the singular points it returns their finite values (az = 0, rdot = |v| at the sensor).
template <int M>
SphericalVec<M> spherical_measurement(const Vec3& d, const Vec3& v, AzimuthConvention c) {
  static_assert(M == 3 || M == 4);
  SphericalVec<M> h;
  h.template head<3>() = enu_to_spherical(d, c);
  if constexpr (M == 4) h(3) = range_rate(d, v);
  return h;
}

namespace detail {
// The Jacobian fill shared by spherical_measurement_jacobian and spherical_measurement_with_jacobian,
// given the horizontal range rho_true = hypot(x, y) and the range r = hypot(rho_true, z) the caller
// has already computed (so the two entry points give the same values bit for bit), into an H the
// caller has zeroed (each caller zeroes it first, where it always stood, so the compiled code is
// that of the two separate fills). Inline and allocation-free: it runs per measurement update in
// filter.ekf and filter.imm.
template <int M>
inline SphericalSingularity fill_spherical_jacobian(const Vec3& d, const Vec3& v, AzimuthConvention c,
                                                    double rho_true, double r, SphericalJacobian<M>& H) {
  static_assert(M == 3 || M == 4);
  if (!(r >= kMinRange)) return SphericalSingularity::AtSensor;
  const bool zenith = rho_true < kZenithFraction * r;
  // Unit horizontal direction (any one straight overhead); only the azimuth row's 1/rho is floored.
  const double ux = rho_true > 0.0 ? d.x() / rho_true : 1.0, uy = rho_true > 0.0 ? d.y() / rho_true : 0.0;
  const double inv_rho = 1.0 / std::max(rho_true, kZenithFraction * r);
  const double r2 = r * r;
  H.template block<1, 3>(0, 0) = d.transpose() / r;
  if (c == AzimuthConvention::NorthClockwise) {
    H(1, 0) = uy * inv_rho;
    H(1, 1) = -ux * inv_rho;
  } else {
    H(1, 0) = -uy * inv_rho;
    H(1, 1) = ux * inv_rho;
  }
  H(2, 0) = -ux * d.z() / r2;
  H(2, 1) = -uy * d.z() / r2;
  H(2, 2) = rho_true / r2;
  if constexpr (M == 4) {
    const double dv = d.dot(v);
    H.template block<1, 3>(3, 0) = (v * r2 - dv * d).transpose() / (r2 * r);
    H.template block<1, 3>(3, 3) = d.transpose() / r;
  }
  return zenith ? SphericalSingularity::Zenith : SphericalSingularity::None;
}
}  // namespace detail

// Analytic Jacobian of spherical_measurement. With rho = hypot(x, y), r = |d|, rdot = d.v / r:
//   dr/dd = d'/r                                  dr/dv = 0
//   north_clockwise  az = atan2(x, y): daz/dd = [ y, -x, 0] / rho^2
//   x_counterclockw. az = atan2(y, x): daz/dd = [-y,  x, 0] / rho^2
//   el = atan2(z, rho): del/dd = [-x z / (r^2 rho), -y z / (r^2 rho), rho / r^2]
//   drdot/dd = (v r^2 - (d.v) d)' / r^3            drdot/dv = d'/r
// (paper 000 eq 3.24 prints z(x xdot + y ydot) in the rdot row's z column as x(...): a typo.)
template <int M>
SphericalSingularity spherical_measurement_jacobian(const Vec3& d, const Vec3& v, AzimuthConvention c,
                                                    SphericalJacobian<M>& H) {
  static_assert(M == 3 || M == 4);
  H.setZero();
  const double rho_true = std::hypot(d.x(), d.y());
  const double r = std::hypot(rho_true, d.z());
  return detail::fill_spherical_jacobian<M>(d, v, c, rho_true, r, H);
}

// spherical_measurement and spherical_measurement_jacobian in one: the same values bit for bit
// (the same expressions), with the horizontal range and the range computed once for both.
template <int M>
SphericalSingularity spherical_measurement_with_jacobian(const Vec3& d, const Vec3& v, AzimuthConvention c,
                                                         SphericalVec<M>& h, SphericalJacobian<M>& H) {
  static_assert(M == 3 || M == 4);
  H.setZero();
  const double rho_true = std::hypot(d.x(), d.y());
  const double r = std::hypot(rho_true, d.z());
  h(0) = r;
  h(1) = c == AzimuthConvention::NorthClockwise ? std::atan2(d.x(), d.y()) : std::atan2(d.y(), d.x());
  h(2) = std::atan2(d.z(), rho_true);
  if constexpr (M == 4) h(3) = range_rate(d, v);
  return detail::fill_spherical_jacobian<M>(d, v, c, rho_true, r, H);
}

// z - h with the azimuth difference wrapped to (-pi, pi]. Elevation lies in [-pi/2, pi/2] and
// is not wrapped.
template <int M>
SphericalVec<M> spherical_residual(const SphericalVec<M>& z, const SphericalVec<M>& h) {
  SphericalVec<M> nu = z - h;
  nu(1) = wrap_angle(nu(1));
  return nu;
}

}  // namespace trackflow
