// Purpose: spherical <-> ENU geometry for both azimuth conventions, its exact Jacobian, and angle wrapping.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>
#include <numbers>
#include <string>

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

// A vector in the sensor's own axes (Measurement::sensor_axes) -> the frame's axes, and back.
inline Vec3 sensor_to_frame(const Measurement& m, const Vec3& v) { return m.sensor_level ? v : Vec3(m.sensor_axes * v); }
inline Vec3 frame_to_sensor(const Measurement& m, const Vec3& v) {
  return m.sensor_level ? v : Vec3(m.sensor_axes.transpose() * v);
}

// The elevation a detection's position is taken at: its own, or 0 for a 2-D radar (Polar), whose
// target is placed in the radar's horizontal plane (ground range = measured range).
inline double measured_elevation(const Measurement& m) { return m.frame == Frame::Polar ? 0.0 : m.value(2); }

// A measurement's position in the frame. Spherical and Polar: sensor position plus the converted
// offset, turned into the frame's axes when the sensor is tilted; Cartesian as it is; Planar in the
// plane z = 0.
inline Vec3 measured_position(const Measurement& m) {
  switch (m.frame) {
    case Frame::Cartesian: return m.value.head<3>();
    case Frame::Planar: return Vec3(m.value(0), m.value(1), 0.0);
    default:
      return sensor_to_frame(m, spherical_to_enu(m.value(0), m.value(1), measured_elevation(m), m.azimuth)) +
             m.sensor_position;
  }
}

// The covariance of measured_position from the measurement's position covariance: J R J' (the
// exact first-order transform) for Spherical and Polar, R for Cartesian; a 2-D frame's position
// has zero variance in the direction it does not measure (z, or the radar's vertical).
inline Mat3 measured_position_covariance(const Measurement& m, const MeasCov& R) {
  const int k = position_values(m.frame);
  Mat3 Rp = Mat3::Zero();
  Rp.topLeftCorner(k, k) = R.topLeftCorner(k, k);
  if (m.frame == Frame::Cartesian || m.frame == Frame::Planar) return Rp;
  Mat3 J = spherical_to_enu_jacobian(m.value(0), m.value(1), measured_elevation(m), m.azimuth);
  if (!m.sensor_level) J = m.sensor_axes * J;
  return J * Rp * J.transpose();
}

// nu = z - h with the azimuth difference wrapped to (-pi, pi] in the frames that have one: the
// one place a residual learns its frame's manifold.
inline void wrap_residual(Frame f, MeasVec& nu) {
  if (has_azimuth(f)) nu(1) = wrap_angle(nu(1));
}

// The text of the error a consumer that works in the frame's axes gives for a tilted sensor
// (empty: the sensor is level). Callers throw it as a DataError with their node's name.
inline std::string tilted_sensor_message(const Measurement& m) {
  if (m.sensor_level) return {};
  return "the measurement at t=" + std::to_string(m.time) + " s comes from sensor " + std::to_string(m.sensor) +
         ", whose horizon is tilted against the frame (a geodetic site away from pipeline.frame_origin); this node "
         "works in the frame's axes only: use filter.ekf or filter.ukf, or anchor the frame at that sensor";
}

}  // namespace trackflow
