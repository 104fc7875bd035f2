// Purpose: spherical <-> ENU geometry for both azimuth conventions, its exact Jacobian, and angle wrapping.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>
#include <numbers>

namespace trackflow {

// Wraps to (-pi, pi].
inline double wrap_angle(double a) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  if (a > -std::numbers::pi && a <= std::numbers::pi) return a;
  a = std::fmod(a + std::numbers::pi, two_pi);
  if (a <= 0.0) a += two_pi;
  return a - std::numbers::pi;
}

// Horizontal direction cosines (east, north) of an azimuth, and their derivative.
struct AzimuthBasis {
  double east, north, d_east, d_north;
};
inline AzimuthBasis azimuth_basis(double az, AzimuthConvention c) {
  const double s = std::sin(az), co = std::cos(az);
  if (c == AzimuthConvention::NorthClockwise) return {s, co, co, -s};
  return {co, s, -s, co};
}

// [r, az, el] -> position relative to the sensor, ENU.
inline Vec3 spherical_to_enu(double r, double az, double el, AzimuthConvention c) {
  const auto b = azimuth_basis(az, c);
  const double ce = std::cos(el), se = std::sin(el);
  return {r * ce * b.east, r * ce * b.north, r * se};
}

// d(x, y, z) / d(r, az, el): columns are r, az, el.
inline Mat3 spherical_to_enu_jacobian(double r, double az, double el, AzimuthConvention c) {
  const auto b = azimuth_basis(az, c);
  const double ce = std::cos(el), se = std::sin(el);
  Mat3 J;
  J << ce * b.east, r * ce * b.d_east, -r * se * b.east,
       ce * b.north, r * ce * b.d_north, -r * se * b.north,
       se, 0.0, r * ce;
  return J;
}

// Position relative to the sensor -> [r, az, el]. At the sensor or the zenith the azimuth
// is undefined; atan2(0, 0) = 0 gives a finite answer there and callers that linearise
// must not rely on it (the Jacobian is singular).
inline Vec3 enu_to_spherical(const Vec3& d, AzimuthConvention c) {
  const double horiz = std::hypot(d.x(), d.y());
  const double r = std::hypot(horiz, d.z());
  const double az = c == AzimuthConvention::NorthClockwise ? std::atan2(d.x(), d.y())
                                                           : std::atan2(d.y(), d.x());
  const double el = std::atan2(d.z(), horiz);
  return {r, az, el};
}

// Range rate of a target at relative position d with relative velocity v.
inline double range_rate(const Vec3& d, const Vec3& v) {
  const double r = d.norm();
  return r > 0.0 ? d.dot(v) / r : v.norm();
}

}  // namespace trackflow
