// Purpose: the EKF measurement update of a Cartesian radar state on [r, az, el(, rdot)] (filter.ekf and each mode of filter.imm): analytic Jacobian, zenith conditioning, structured Joseph update.
#pragma once

#include "zenith_linearisation.hpp"

#include <trackflow/items.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Core>

namespace trackflow::cartesian_filter {

enum class EkfOutcome {
  Used,
  AtSensor,             // predicted position at the sensor: no direction to linearise about
  NotPositiveDefinite,  // S not positive definite: x and P untouched
};

// What one update saw: the innovation and its covariance (what an IMM's likelihood needs) and
// what the zenith conditioning did.
template <int M>
struct EkfInnovation {
  Eigen::Matrix<double, M, 1> nu;
  Eigen::Matrix<double, M, M> S;
  double nis = 0.0;
  double det_S = 0.0;  // det S, from the update's Cholesky factor
  bool azimuth_dropped = false, azimuth_deweighted = false;
};

// Curvature of the angles over the predicted horizontal uncertainty (zenith_linearisation.hpp):
// negligible at ordinary ranges, it de-weights the azimuth smoothly as the target nears the
// zenith. When the zenith itself is within 3 sigma of the predicted horizontal position the
// azimuth may flip by pi and is dropped: zero row, zero innovation, R decorrelated (an
// infinitely uncertain azimuth; range, elevation and range rate still update).
template <int N, int M>
void condition_near_zenith(const Eigen::Matrix<double, N, N>& P, const int idx[6], const Measurement& m, const Vec3& d,
                           SphericalSingularity sing, SphericalJacobian<M>& J, SphericalVec<M>& nu,
                           Eigen::Matrix<double, M, M>& R, EkfInnovation<M>& out) {
  Eigen::Matrix2d Ph;
  Ph << P(idx[0], idx[0]), P(idx[0], idx[1]), P(idx[1], idx[0]), P(idx[1], idx[1]);
  if (!m.sensor_level) {  // the horizontal block in the sensor's own axes
    Mat3 Pp;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Pp(i, j) = P(idx[i], idx[j]);
    Ph = (m.sensor_axes.transpose() * Pp * m.sensor_axes).template topLeftCorner<2, 2>();
  }
  const ekf::AngleCurvature curvature = ekf::angle_curvature_variance(d, Ph, kZenithFraction * d.norm());
  const double raz = R(1, 1);
  R(2, 2) += curvature.elevation;
  out.azimuth_dropped = sing == SphericalSingularity::Zenith || curvature.azimuth_unusable;
  if (out.azimuth_dropped) {
    J.row(1).setZero();
    nu(1) = 0.0;
    R.row(1).setZero();
    R.col(1).setZero();
    R(1, 1) = raz > 0.0 ? raz : 1.0;
  } else {
    R(1, 1) += curvature.azimuth;
    out.azimuth_deweighted = curvature.azimuth > raz;
  }
}

// P H' and the lower triangle of S = H P H' + R from a radar Jacobian J (M x 6, columns
// [x y z vx vy vz] in the sensor's axes; turned into the frame's here for a tilted sensor,
// dh/dx_frame = dh/dd_sensor A') whose rows depend on the position only, but for row `rate_row`
// (the range rate, also on the velocity; -1: none). Shared by the [r, az, el(, rdot)] update below
// and the 2-D radar's [r, az(, rdot)] one (ekf_polar_update.hpp).
template <int N, int M>
void radar_gain_terms(const Eigen::Matrix<double, N, N>& P, const int idx[6], const Measurement& m, int rate_row,
                      Eigen::Matrix<double, M, 6>& J, const Eigen::Matrix<double, M, M>& R,
                      Eigen::Matrix<double, N, M>& PHt, Eigen::Matrix<double, M, M>& S) {
  if (!m.sensor_level) {
    const Mat3 At = m.sensor_axes.transpose();
    for (int k = 0; k < M; ++k) {
      const Eigen::RowVector3d jp = J.template block<1, 3>(k, 0) * At;
      J.template block<1, 3>(k, 0) = jp;
      if (k == rate_row) {
        const Eigen::RowVector3d jv = J.template block<1, 3>(k, 3) * At;
        J.template block<1, 3>(k, 3) = jv;
      }
    }
  }
  for (int k = 0; k < M; ++k)
    for (int r = 0; r < N; ++r) {
      double s = P(r, idx[0]) * J(k, 0) + P(r, idx[1]) * J(k, 1) + P(r, idx[2]) * J(k, 2);
      if (k == rate_row) s += P(r, idx[3]) * J(k, 3) + P(r, idx[4]) * J(k, 4) + P(r, idx[5]) * J(k, 5);
      PHt(r, k) = s;
    }
  for (int k = 0; k < M; ++k)
    for (int l = k; l < M; ++l) {
      const int c = l == rate_row ? 6 : 3;  // H P H' = H (P H'): row l of H against column k of P H'
      double s = R(l, k);
      for (int j = 0; j < c; ++j) s += J(l, j) * PHt(idx[j], k);
      S(l, k) = s;
    }
}

// h linearised at the predicted state x (idx: the state indices of [x y z vx vy vz]); R is the
// measurement's M x M covariance; `curvature`: condition near the zenith (filter.ekf's zenith:
// curvature). H = dh/dx is non-zero only in the position columns (and, for the range rate, the
// velocity columns): P H' and H P H' are formed from those (kalman.hpp, joseph_update_cross),
// never the M x N H or an N x N x N product.
//
// ekf_radar_linearise is the update up to S: the innovation nu = z - h (azimuth wrapped, zenith
// conditioned), S's lower triangle and P H'; it changes nothing, so a track's predicted measurement
// (Estimator::predict_measurement, with z = 0: nu = -h) is the update's own linearisation, without
// a copy of the estimator.
template <int N, int M>
EkfOutcome ekf_radar_linearise(const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& P,
                               const int idx[6], const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured,
                               bool curvature, EkfInnovation<M>& out, Eigen::Matrix<double, N, M>& PHt) {
  using MatM = Eigen::Matrix<double, M, M>;
  out.azimuth_dropped = out.azimuth_deweighted = false;
  // In the sensor's own axes (a tilted sensor: Measurement::sensor_axes); J is turned back into
  // the frame's below.
  const Vec3 d = frame_to_sensor(m, Vec3(x(idx[0]), x(idx[1]), x(idx[2])) - m.sensor_position);
  const Vec3 v = frame_to_sensor(m, Vec3(x(idx[3]), x(idx[4]), x(idx[5])));
  SphericalJacobian<M> J;  // columns [x y z vx vy vz]
  SphericalVec<M> h;
  const SphericalSingularity sing = spherical_measurement_with_jacobian<M>(d, v, m.azimuth, h, J);
  if (sing == SphericalSingularity::AtSensor) return EkfOutcome::AtSensor;
  const SphericalVec<M> z = m.value.template head<M>();
  SphericalVec<M> nu = spherical_residual<M>(z, h);
  MatM R = R_measured;
  if (curvature) condition_near_zenith<N, M>(P, idx, m, d, sing, J, nu, R, out);
  radar_gain_terms<N, M>(P, idx, m, M == 4 ? 3 : -1, J, R, PHt, out.S);
  out.nu = nu;
  return EkfOutcome::Used;
}

template <int N, int M>
EkfOutcome ekf_radar_update(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P, const int idx[6],
                            const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured, bool curvature,
                            EkfInnovation<M>& out) {
  Eigen::Matrix<double, N, M> PHt;
  if (ekf_radar_linearise<N, M>(x, P, idx, m, R_measured, curvature, out, PHt) == EkfOutcome::AtSensor)
    return EkfOutcome::AtSensor;
  if (joseph_update_cross<N, M>(x, P, out.nu, PHt, out.S, out.nis, nullptr, &out.det_S)) return EkfOutcome::Used;
  return EkfOutcome::NotPositiveDefinite;
}

}  // namespace trackflow::cartesian_filter
