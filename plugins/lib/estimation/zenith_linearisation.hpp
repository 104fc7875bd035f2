// Purpose: the second-order (curvature) variance of the azimuth and elevation near the zenith, added to R so the EKF stays consistent there.
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace trackflow::ekf {

// Linearising h about the predicted position ignores the curvature term 1/2 dᵀ A d of each
// angle (A = Hessian w.r.t. the horizontal position error d ~ N(0, Ph)). Its variance,
// 1/2 tr(A Ph A Ph), is negligible at ordinary ranges but grows like 1/rho^4 as the horizontal
// range rho -> 0: there the azimuth is not a smooth function of the state over its uncertainty.
// Adding it to R (the covariance part of the second-order EKF, Bar-Shalom, Li & Kirubarajan 2001
// §10.3.3) de-weights the angles smoothly instead of trusting a linearisation that no longer
// holds. In the horizontal basis (u_par along the line of sight, u_perp across it), with
// a = Ph_par,par, b = Ph_perp,perp, c = Ph_par,perp:
//   azimuth:   A = ±(u_par u_perpᵀ + u_perp u_parᵀ) / rho^2      -> var = (a b + c^2) / rho^4
//   elevation: A ≈ -z / (r^2 rho) u_perp u_perpᵀ (the cone's curvature; the other second
//              derivatives are O(1/r^2))                         -> var = (z b / (r^2 rho))^2 / 2
// rho is floored at rho_floor. A Taylor expansion cannot see the azimuth's jump by pi across the
// zenith: when the zenith lies within kZenithSigmas standard deviations of the predicted
// horizontal position (rho^2 < kZenithSigmas^2 (a + b)), `azimuth_unusable` is set and the
// azimuth must not be used at all.
inline constexpr double kZenithSigmas = 3.0;

struct AngleCurvature {
  double azimuth = 0.0, elevation = 0.0;  // rad^2
  bool azimuth_unusable = false;
};

inline AngleCurvature angle_curvature_variance(const Vec3& d, const Eigen::Matrix2d& Ph, double rho_floor) {
  const double rho_true = std::hypot(d.x(), d.y());
  const double rho = std::max(rho_true, rho_floor);
  const double r2 = rho * rho + d.z() * d.z();
  const Eigen::Vector2d par = rho_true > 0.0 ? Eigen::Vector2d(d.x() / rho_true, d.y() / rho_true)
                                             : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d perp(-par.y(), par.x());
  const double a = par.dot(Ph * par), b = perp.dot(Ph * perp), c = par.dot(Ph * perp);
  const double rho2 = rho * rho;
  AngleCurvature v;
  v.azimuth = (a * b + c * c) / (rho2 * rho2);
  const double k = d.z() * b / (r2 * rho);
  v.elevation = 0.5 * k * k;
  v.azimuth_unusable = rho_true * rho_true < kZenithSigmas * kZenithSigmas * (a + b);
  return v;
}

}  // namespace trackflow::ekf
