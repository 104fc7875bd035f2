// Purpose: the 13-state augmented model of paper 004 (eq 7-10): Cartesian position, velocity and previous velocity per axis, range, azimuth, elevation and the refraction bias b, with its propagation and analytic Jacobian.
#pragma once

#include "estimation/refraction_ekf_state.hpp"
#include "physics/refraction.hpp"

#include <trackflow/items.hpp>

#include <Eigen/Core>

#include <cmath>

namespace trackflow::refraction_ekf {

// The state order (kN, Index, pos/vel/prev) and its names live in plugins/lib
// (estimation/refraction_ekf_state.hpp): sink.elevation_error reads the bias by that index.
using State = Eigen::Matrix<double, kN, 1>;
using Matrix = Eigen::Matrix<double, kN, kN>;

// How the Cartesian position is advanced. euler: x + T vx (paper 004 §2.1.3, the acceleration
// enters only through the noise); adams_bashforth2: x + T (3 vx - vx_prev) / 2, i.e. x + T vx +
// T^2 a / 2 with the model's own acceleration a = (vx - vx_prev) / T, exact for constant
// acceleration.
enum class Position { Euler, AdamsBashforth2 };

struct Model {
  sim::ClarkModel clark;   // its `below` is Hold: below 2 deg b-dot = 0
  double azimuth_sign = -1.0;  // d(azimuth) = sign (x vy - vx y) / (x^2 + y^2): -1 north-clockwise, +1 from x
  bool bias = true;            // false: no bias state (b stays 0, its dynamics off)
  Position position = Position::Euler;
};

// Rates of the radar quantities from the Cartesian state (paper 004 §2.1.3):
//   rho-dot   = (x vx + y vy + z vz) / r
//   phi-dot   = sign (x vy - vx y) / s^2
//   theta-dot = (vz s^2 - z (x vx + y vy)) / (r^2 s)
// with r = |p|, s = |p_xy|; s^2 is kept >= 1 m^2 so the rates stay finite over the radar.
struct Rates {
  double range = 0.0, azimuth = 0.0, elevation = 0.0;
  // Partial derivatives with respect to [x, y, z] and [vx, vy, vz].
  Eigen::Matrix<double, 3, 3> d_position = Eigen::Matrix<double, 3, 3>::Zero();  // rows: range, az, el
  Eigen::Matrix<double, 3, 3> d_velocity = Eigen::Matrix<double, 3, 3>::Zero();
};

inline Rates rates(const State& X, double azimuth_sign) {
  const double x = X(kX), y = X(kY), z = X(kZ);
  const double vx = X(kX + kVel), vy = X(kY + kVel), vz = X(kZ + kVel);
  const double s2 = std::max(x * x + y * y, 1.0), s = std::sqrt(s2);
  const double r2 = s2 + z * z, r = std::sqrt(r2);
  const double pv = x * vx + y * vy + z * vz, q = x * vx + y * vy, cross = x * vy - vx * y;
  Rates k;
  k.range = pv / r;
  k.azimuth = azimuth_sign * cross / s2;
  const double g = vz * s2 - z * q;
  k.elevation = g / (r2 * s);
  // d rho-dot: v / r - (p.v) p / r^3 ; p / r.
  const Vec3 p(x, y, z), v(vx, vy, vz);
  k.d_position.row(0) = (v / r - pv / (r2 * r) * p).transpose();
  k.d_velocity.row(0) = (p / r).transpose();
  // d phi-dot.
  k.d_position(1, 0) = azimuth_sign * (vy / s2 - 2 * x * cross / (s2 * s2));
  k.d_position(1, 1) = azimuth_sign * (-vx / s2 - 2 * y * cross / (s2 * s2));
  k.d_velocity(1, 0) = -azimuth_sign * y / s2;
  k.d_velocity(1, 1) = azimuth_sign * x / s2;
  // d theta-dot: quotient rule on g / (r^2 s), with d(r^2 s)/dx = 2 x s + r^2 x / s and
  // d(r^2 s)/dz = 2 z s.
  const double th = k.elevation, denom = r2 * s;
  k.d_position(2, 0) = (2 * x * vz - z * vx) / denom - th * (2 * x / r2 + x / s2);
  k.d_position(2, 1) = (2 * y * vz - z * vy) / denom - th * (2 * y / r2 + y / s2);
  k.d_position(2, 2) = -q / denom - th * 2 * z / r2;
  k.d_velocity(2, 0) = -z * x / denom;
  k.d_velocity(2, 1) = -z * y / denom;
  k.d_velocity(2, 2) = s / r2;
  return k;
}

// X_{k+1} = f(X_k) over T (paper 004 §2.1.3; process noise added by the filter):
//   velocity:      v' = v + T a, a = (v - v_prev) / T, i.e. 2 v - v_prev;  v_prev' = v
//   position:      Euler x + T v, or Adams-Bashforth x + T (3 v - v_prev) / 2
//   radar states:  rho' = rho + T rho-dot, phi' = phi + T phi-dot, theta' = theta + T theta-dot
//   bias:          b' = b + T b-dot, b-dot = b'(theta) theta-dot (Clark, b' at the state's theta)
// and its Jacobian A = df/dX (paper eq 10, corrected: d b-dot/d theta = b''(theta) theta-dot, and
// d b-dot / d(p, v) = b'(theta) d theta-dot / d(p, v)).
inline State propagate(const State& X, double T, const Model& m, Matrix* A = nullptr) {
  const Rates k = rates(X, m.azimuth_sign);
  State Y = X;
  for (int a = 0; a < 3; ++a) {
    const double v = X(vel(a)), vp = X(prev(a));
    Y(pos(a)) = m.position == Position::Euler ? X(pos(a)) + T * v : X(pos(a)) + T * (1.5 * v - 0.5 * vp);
    Y(vel(a)) = 2 * v - vp;
    Y(prev(a)) = v;
  }
  Y(kRange) = X(kRange) + T * k.range;
  Y(kAzimuth) = X(kAzimuth) + T * k.azimuth;
  Y(kElevation) = X(kElevation) + T * k.elevation;
  const sim::ClarkModel::Value c = m.clark.at(X(kElevation));
  Y(kBias) = m.bias ? X(kBias) + T * c.db * k.elevation : 0.0;
  if (A) {
    A->setZero();
    for (int a = 0; a < 3; ++a) {
      (*A)(pos(a), pos(a)) = 1.0;
      if (m.position == Position::Euler) {
        (*A)(pos(a), vel(a)) = T;
      } else {
        (*A)(pos(a), vel(a)) = 1.5 * T;
        (*A)(pos(a), prev(a)) = -0.5 * T;
      }
      (*A)(vel(a), vel(a)) = 2.0;
      (*A)(vel(a), prev(a)) = -1.0;
      (*A)(prev(a), vel(a)) = 1.0;
    }
    for (int i = 0; i < 3; ++i) {
      const int row = kRange + i;
      (*A)(row, row) = 1.0;
      for (int a = 0; a < 3; ++a) {
        (*A)(row, pos(a)) = T * k.d_position(i, a);
        (*A)(row, vel(a)) = T * k.d_velocity(i, a);
      }
    }
    if (m.bias) {
      (*A)(kBias, kBias) = 1.0;
      (*A)(kBias, kElevation) = T * c.d2b * k.elevation;
      for (int a = 0; a < 3; ++a) {
        (*A)(kBias, pos(a)) = T * c.db * k.d_position(2, a);
        (*A)(kBias, vel(a)) = T * c.db * k.d_velocity(2, a);
      }
    }
  }
  return Y;
}

}  // namespace trackflow::refraction_ekf
