// Purpose: the EKF measurement update of a Cartesian radar state on [r, az, el(, rdot)] (filter.ekf and each mode of filter.imm): analytic Jacobian, zenith conditioning, structured Joseph update.
#pragma once

#include "zenith_guard.hpp"
#include "zenith_linearisation.hpp"

#include <trackflow/items.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Core>

#include <string>

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
  bool relinearised = false;  // the iterated update below was used (a prior much wider than the measurement)
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
  const Eigen::Matrix2d Ph = horizontal_covariance<N>(P, idx, m);
  const ekf::AngleCurvature curvature = ekf::angle_curvature_variance(d, Ph, kZenithFraction * d.norm());
  const double raz = R(1, 1);
  R(2, 2) += curvature.elevation;
  out.azimuth_dropped = sing == SphericalSingularity::Zenith || curvature.azimuth_unusable;
  if (out.azimuth_dropped) {
    J.row(1).setZero();
    drop_azimuth_noise<M>(nu, R);
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
// `at` (the iterated update below): linearise about that state instead of x, with the iterated
// EKF's innovation nu = z - h(at) - H (x - at) (the iterated EKF below);
// `curvature_P`: the covariance of that linearisation point's error, over which the zenith
// conditioning is taken (P, the prior's, when linearising about the prediction).
template <int N, int M>
EkfOutcome ekf_radar_linearise(const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& P,
                               const int idx[6], const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured,
                               bool curvature, EkfInnovation<M>& out, Eigen::Matrix<double, N, M>& PHt,
                               const Eigen::Matrix<double, N, 1>* at = nullptr,
                               const Eigen::Matrix<double, N, N>* curvature_P = nullptr) {
  using MatM = Eigen::Matrix<double, M, M>;
  out.azimuth_dropped = out.azimuth_deweighted = out.relinearised = false;
  const Eigen::Matrix<double, N, 1>& xl = at ? *at : x;
  // In the sensor's own axes (a tilted sensor: Measurement::sensor_axes); J is turned back into
  // the frame's below.
  const Vec3 d = frame_to_sensor(m, Vec3(xl(idx[0]), xl(idx[1]), xl(idx[2])) - m.sensor_position);
  const Vec3 v = frame_to_sensor(m, Vec3(xl(idx[3]), xl(idx[4]), xl(idx[5])));
  SphericalJacobian<M> J;  // columns [x y z vx vy vz]
  SphericalVec<M> h;
  const SphericalSingularity sing = spherical_measurement_with_jacobian<M>(d, v, m.azimuth, h, J);
  if (sing == SphericalSingularity::AtSensor) return EkfOutcome::AtSensor;
  const SphericalVec<M> z = m.value.template head<M>();
  SphericalVec<M> nu = spherical_residual<M>(z, h);
  MatM R = R_measured;
  if (curvature) condition_near_zenith<N, M>(curvature_P ? *curvature_P : P, idx, m, d, sing, J, nu, R, out);
  radar_gain_terms<N, M>(P, idx, m, M == 4 ? 3 : -1, J, R, PHt, out.S);
  if (at)  // J is in the frame's axes now; a dropped azimuth's row is zero, so its nu stays 0
    for (int k = 0; k < M; ++k)
      for (int j = 0; j < 6; ++j) nu(k) -= J(k, j) * (x(idx[j]) - xl(idx[j]));
  out.nu = nu;
  return EkfOutcome::Used;
}

// Whether the predicted horizontal position is much less certain than the measurement's: the
// trace of the prior's horizontal covariance above kWidePrior times that of the measured point's
// (at the predicted geometry: along the line of sight (rho/r)^2 var_r + z^2 var_el, across it
// rho^2 var_az, from R's diagonal). When the zenith conditioning over such a prior (a huge q: 1e12
// m2/s3 gives an 18 km sigma per 0.1 s step) acts, it drops or de-weights the azimuth although the
// measurement places the target far from the zenith (issue 27: RMSE 6.2 km where the measurements
// give ~18 m), and a linearisation about the prediction is poor anyway: the update is iterated
// (ekf_radar_update below; filter.ukf likewise when the zenith is within its sigma points' reach).
inline constexpr double kWidePrior = 100.0;
template <int N, int M>
bool prior_much_wider(const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& P, const int idx[6],
                      const Measurement& m, const Eigen::Matrix<double, M, M>& R) {
  const Vec3 d = frame_to_sensor(m, Vec3(x(idx[0]), x(idx[1]), x(idx[2])) - m.sensor_position);
  const double rho2 = d.x() * d.x() + d.y() * d.y(), r2 = rho2 + d.z() * d.z();
  if (!(r2 > 0.0)) return false;
  const double measured = rho2 / r2 * R(0, 0) + d.z() * d.z() * R(2, 2) + rho2 * R(1, 1);
  return horizontal_covariance<N>(P, idx, m).trace() > kWidePrior * measured;
}

// The iterated EKF (Bar-Shalom, Li & Kirubarajan 2001 ch. 10, the iterated EKF; Bell & Cathey,
// IEEE TAC 38(2), 1993: each iteration is a Gauss-Newton step on the MAP cost): linearise about x_i, x_{i+1} = x + K_i (z - h(x_i) - H_i (x - x_i)), from x_0 = x
// (the plain EKF's step), until the position moves by less than kIterationTolerance of the range
// or after kMaxIterations. The final step is linearised about the last iterate with the zenith
// conditioning taken over the covariance of its error (the last pass's posterior: the error of a
// point fixed by the measurement, not the prior's), and updates x, P in Joseph form with that H.
inline constexpr int kMaxIterations = 10;
inline constexpr double kIterationTolerance = 1e-9;
template <int N, int M>
EkfOutcome ekf_radar_iterated_update(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P,
                                     const int idx[6], const Measurement& m,
                                     const Eigen::Matrix<double, M, M>& R_measured, EkfInnovation<M>& out) {
  Eigen::Matrix<double, N, 1> xi = x, x1;
  Eigen::Matrix<double, N, N> P1;
  Eigen::Matrix<double, N, M> PHt;
  EkfInnovation<M> pass;
  for (int it = 0; it < kMaxIterations; ++it) {
    if (ekf_radar_linearise<N, M>(x, P, idx, m, R_measured, false, pass, PHt, &xi) == EkfOutcome::AtSensor)
      return EkfOutcome::AtSensor;
    x1 = x;
    P1 = P;
    if (!joseph_update_cross<N, M>(x1, P1, pass.nu, PHt, pass.S, pass.nis)) return EkfOutcome::NotPositiveDefinite;
    const Vec3 step(x1(idx[0]) - xi(idx[0]), x1(idx[1]) - xi(idx[1]), x1(idx[2]) - xi(idx[2]));
    const double range = (Vec3(x1(idx[0]), x1(idx[1]), x1(idx[2])) - m.sensor_position).norm();
    xi = x1;
    if (!(step.norm() > kIterationTolerance * range)) break;
  }
  if (ekf_radar_linearise<N, M>(x, P, idx, m, R_measured, true, out, PHt, &xi, &P1) == EkfOutcome::AtSensor)
    return EkfOutcome::AtSensor;
  out.relinearised = true;
  if (joseph_update_cross<N, M>(x, P, out.nu, PHt, out.S, out.nis, nullptr, &out.det_S)) return EkfOutcome::Used;
  return EkfOutcome::NotPositiveDefinite;
}

// What filter.ekf and filter.ukf report at the end of a run in which the iterated update was used.
inline std::string relinearised_text(int count, int updates) {
  return "predicted horizontal uncertainty more than " + std::to_string(static_cast<int>(kWidePrior)) +
         " times the measurement's (in variance) at " + std::to_string(count) + " of " + std::to_string(updates) +
         " updates: the update was iterated about the measured position (iterated EKF) there instead of linearised "
         "about the prediction (see q)";
}

// `iterate`: whether a prior much wider than the measurement may take the iterated update
// (filter.ekf); filter.imm's modes pass false: their likelihoods and the gate are the single
// linearisation's, and the IMM's results stay what they were.
template <int N, int M>
EkfOutcome ekf_radar_update(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P, const int idx[6],
                            const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured, bool curvature,
                            EkfInnovation<M>& out, bool iterate = true) {
  Eigen::Matrix<double, N, M> PHt;
  if (ekf_radar_linearise<N, M>(x, P, idx, m, R_measured, curvature, out, PHt) == EkfOutcome::AtSensor)
    return EkfOutcome::AtSensor;
  // The zenith conditioning acted on a prediction much wider than the measurement: the measurement,
  // not the prior, says where the target is (and whether it is near the zenith).
  if (iterate && (out.azimuth_dropped || out.azimuth_deweighted) && prior_much_wider<N, M>(x, P, idx, m, R_measured))
    return ekf_radar_iterated_update<N, M>(x, P, idx, m, R_measured, out);
  if (joseph_update_cross<N, M>(x, P, out.nu, PHt, out.S, out.nis, nullptr, &out.det_S)) return EkfOutcome::Used;
  return EkfOutcome::NotPositiveDefinite;
}

}  // namespace trackflow::cartesian_filter
