// Purpose: paper 000's spherical-coordinate constant-acceleration model (eq 3.42-3.58): propagation f, its Jacobian F, process noise Q, and the map to ENU.
#pragma once

#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/motion.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace trackflow::ekf_spherical {

// rho = [R, v_r, v̇_r, θ, v_h, v̇_h, φ, v_v, v̇_v] (eq 3.42), relative to the sensor:
// v_r = Ṙ, v_h = R cos φ θ̇, v_v = R φ̇ (eq 3.41); v̇_* are the time derivatives of those scalars,
// not the components of the Cartesian acceleration in the local basis.
enum Index : int { kR = 0, kVr, kAr, kTheta, kVh, kAh, kPhi, kVv, kAv };
inline constexpr int kDim = 9;
using State = Eigen::Matrix<double, kDim, 1>;
using Matrix = Eigen::Matrix<double, kDim, kDim>;
using EnuJacobian = Eigen::Matrix<double, 6, kDim>;

// The propagation divides by R and R cos φ and multiplies by tan φ. Those coefficients are
// evaluated at R floored to min_range and φ clamped to ±max_elevation, so f, F and Q stay finite
// at the sensor and straight overhead (where the model itself is meaningless).
struct Guard {
  double max_elevation = 89.0 * std::numbers::pi / 180.0;
  double min_range = 1.0;
};

// The coefficients' point of evaluation and whether the guard moved it.
struct Coefficients {
  double R;            // max(R, min_range)
  double cos_phi, tan_phi, sec2_phi;
  double Rh;           // R cos φ (horizontal range)
  bool range_guarded;  // R < min_range: the coefficients no longer depend on R
  bool elevation_guarded;
};

inline Coefficients coefficients(const State& x, const Guard& g) {
  Coefficients c;
  c.range_guarded = !(x(kR) > g.min_range);
  c.R = c.range_guarded ? g.min_range : x(kR);
  const double phi = x(kPhi);
  c.elevation_guarded = !(std::abs(phi) < g.max_elevation);
  const double phi_e = c.elevation_guarded ? std::copysign(g.max_elevation, phi) : phi;
  c.cos_phi = std::cos(phi_e);
  c.tan_phi = std::tan(phi_e);
  c.sec2_phi = 1.0 / (c.cos_phi * c.cos_phi);
  c.Rh = c.R * c.cos_phi;
  return c;
}

// x <- f(x) over T (eq 3.49-3.57 with 3.46/3.47 for θ̈, φ̈): second-order Taylor steps of R, θ, φ;
// v̇_r, v̇_h, v̇_v held constant. θ is left unwrapped (the caller wraps).
inline void propagate(State& x, double T, const Guard& g) {
  const Coefficients c = coefficients(x, g);
  const double vr = x(kVr), ar = x(kAr), vh = x(kVh), ah = x(kAh), vv = x(kVv), av = x(kAv);
  const double theta_dd_Rh = ah - (vh / c.R) * (vr - vv * c.tan_phi);  // R_h θ̈ (eq 3.46)
  const double phi_dd_R = av - vr * vv / c.R;                            // R φ̈ (eq 3.47)
  x(kR) += T * vr + 0.5 * T * T * ar;
  x(kVr) += T * ar;
  x(kTheta) += (T / c.Rh) * (vh + 0.5 * T * theta_dd_Rh);
  x(kVh) += T * ah;
  x(kPhi) += (T / c.R) * (vv + 0.5 * T * phi_dd_R);
  x(kVv) += T * av;
}

// F = ∂f/∂x at x (the f above, guard included: where the guard holds R or φ the coefficients'
// derivatives with respect to them are zero). Derived from eq 3.52 and 3.55; see docs/filters.md
// for the entries the paper's eq 3.60 prints wrongly.
inline void jacobian(const State& x, double T, const Guard& g, Matrix& F) {
  const Coefficients c = coefficients(x, g);
  const double vr = x(kVr), vh = x(kVh), ah = x(kAh), vv = x(kVv), av = x(kAv);
  const double R = c.R, Rh = c.Rh, t = c.tan_phi, T2 = T * T;
  const double dR = c.range_guarded ? 0.0 : 1.0, dphi = c.elevation_guarded ? 0.0 : 1.0;
  F.setIdentity();
  F(kR, kVr) = T;
  F(kR, kAr) = 0.5 * T2;
  F(kVr, kAr) = T;
  F(kVh, kAh) = T;
  F(kVv, kAv) = T;
  // θ row.
  F(kTheta, kR) = dR * (-(T * vh / (R * Rh)) * (1.0 + (T / R) * (vv * t - vr)) - T2 * ah / (2.0 * R * Rh));
  F(kTheta, kVr) = -T2 * vh / (2.0 * R * Rh);
  F(kTheta, kVh) = (T / Rh) * (1.0 + (T / (2.0 * R)) * (vv * t - vr));
  F(kTheta, kAh) = T2 / (2.0 * Rh);
  const double theta_dd_Rh = ah - (vh / R) * (vr - vv * t);
  F(kTheta, kPhi) = dphi * ((T * t / Rh) * (vh + 0.5 * T * theta_dd_Rh) + T2 * vh * vv * c.sec2_phi / (2.0 * R * Rh));
  F(kTheta, kVv) = T2 * vh * t / (2.0 * R * Rh);
  // φ row.
  F(kPhi, kR) = dR * (-(T * vv / (R * R)) * (1.0 - T * vr / R) - T2 * av / (2.0 * R * R));
  F(kPhi, kVr) = -T2 * vv / (2.0 * R * R);
  F(kPhi, kVv) = (T / R) * (1.0 - T * vr / (2.0 * R));
  F(kPhi, kAv) = T2 / (2.0 * R);
}

// Paper 000 eq 3.58 puts q_θ Q1 and q_φ Q1 on [θ, v_h, v̇_h] and [φ, v_v, v̇_v], which mixes rad
// and m in one block. Here each channel has white jerk on its linear chain (v_r, v_h or v_v
// driven by a jerk of PSD q in m2/s5, Q1 of eq 3.19/3.58); the angle rows carry the arc length
// divided by the range it is measured along (δθ = δs_h / R_h, δφ = δs_v / R, R frozen over T):
//   Q = G blkdiag(q_r Q1, q_h Q1, q_v Q1) G,  G = diag(1, 1, 1, 1/R_h, 1, 1, 1/R, 1, 1).
// unit_Q1 is ConstantAcceleration::axis_noise_continuous(T, 1).
inline void process_noise(const State& x, const Eigen::Matrix3d& unit_Q1, const double q[3], const Guard& g,
                          Matrix& Q) {
  const Coefficients c = coefficients(x, g);
  const double angle_scale[3] = {1.0, 1.0 / c.Rh, 1.0 / c.R};
  Q.setZero();
  for (int ch = 0; ch < 3; ++ch) {
    Eigen::Matrix3d B = q[ch] * unit_Q1;
    B.row(0) *= angle_scale[ch];
    B.col(0) *= angle_scale[ch];
    Q.block<3, 3>(3 * ch, 3 * ch) = B;
  }
}

// A state propagated over the top (|φ| > π/2) names the same point and velocity as
// (θ + π, ±π − φ) with v_h, v̇_h, v_v, v̇_v negated (e_θ and e_φ both flip). Measured elevations lie
// in [−π/2, π/2] and the measured azimuth jumps by π at the pass, so the state is folded back to
// match them. The map is affine with derivative D = diag(1,1,1, 1,−1,−1, −1,−1,−1): P <- D P D.
// Returns whether it folded.
inline bool fold_over_zenith(State& x, Matrix& P) {
  constexpr double half_pi = std::numbers::pi / 2;
  if (std::abs(x(kPhi)) <= half_pi) return false;
  x(kTheta) = wrap_angle(x(kTheta) + std::numbers::pi);
  x(kPhi) = std::copysign(std::numbers::pi, x(kPhi)) - x(kPhi);
  static constexpr int flipped[5] = {kVh, kAh, kPhi, kVv, kAv};
  for (int i : flipped) {
    x(i) = i == kPhi ? x(i) : -x(i);
    P.row(i) *= -1.0;
    P.col(i) *= -1.0;
  }
  return true;
}

// Unit vectors of the local spherical basis in ENU for either azimuth convention: e_r along the
// line of sight, e_θ toward increasing θ (horizontal), e_φ toward increasing φ (paper eq 3.33-3.35
// for north_clockwise; eq 3.35's y component should read −cos θ sin φ).
struct LocalBasis {
  Vec3 e_r, e_theta, e_phi, horizontal;  // horizontal: unit (east, north) direction of θ
};
inline LocalBasis local_basis(double theta, double phi, AzimuthConvention conv) {
  const AzimuthBasis b = azimuth_basis(theta, conv);
  const double cp = std::cos(phi), sp = std::sin(phi);
  return {Vec3(cp * b.east, cp * b.north, sp), Vec3(b.d_east, b.d_north, 0.0), Vec3(-sp * b.east, -sp * b.north, cp),
          Vec3(b.east, b.north, 0.0)};
}

// [position, velocity] relative to the sensor: p = R e_r, v = v_r e_r + v_h e_θ + v_v e_φ
// (eq 3.39, 3.40), and optionally its Jacobian with respect to the 9 states.
inline Vec6 to_enu(const State& x, AzimuthConvention conv, EnuJacobian* J = nullptr) {
  const double R = x(kR), theta = x(kTheta), phi = x(kPhi);
  const double vr = x(kVr), vh = x(kVh), vv = x(kVv);
  const LocalBasis e = local_basis(theta, phi, conv);
  Vec6 out;
  out.head<3>() = R * e.e_r;
  out.tail<3>() = vr * e.e_r + vh * e.e_theta + vv * e.e_phi;
  if (J) {
    J->setZero();
    const double cp = std::cos(phi), sp = std::sin(phi);
    // ∂e_r/∂θ = cos φ e_θ, ∂e_θ/∂θ = −horizontal, ∂e_φ/∂θ = −sin φ e_θ; ∂e_r/∂φ = e_φ, ∂e_φ/∂φ = −e_r.
    J->block<3, 1>(0, kR) = e.e_r;
    J->block<3, 1>(0, kTheta) = R * cp * e.e_theta;
    J->block<3, 1>(0, kPhi) = R * e.e_phi;
    J->block<3, 1>(3, kVr) = e.e_r;
    J->block<3, 1>(3, kVh) = e.e_theta;
    J->block<3, 1>(3, kVv) = e.e_phi;
    J->block<3, 1>(3, kTheta) = (vr * cp - vv * sp) * e.e_theta - vh * e.horizontal;
    J->block<3, 1>(3, kPhi) = vr * e.e_phi - vv * e.e_r;
  }
  return out;
}

}  // namespace trackflow::ekf_spherical
