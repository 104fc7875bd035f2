// Purpose: the EKF measurement update of a Cartesian state on a 2-D surveillance radar's [r, az(, rdot)] (Frame::Polar, filter.ekf): the spherical model's range, azimuth (and range-rate) rows, structured Joseph update.
#pragma once

#include "ekf_radar_update.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Core>

namespace trackflow::cartesian_filter {

// A 2-D radar measures the spherical model's range and azimuth (and range rate) and no
// elevation: h = rows {r, az(, rdot)} of spherical_measurement (spherical_measurement.hpp), its
// Jacobian the same rows of the analytic one. M = 2 ([r, az]) or 3 ([r, az, rdot]). The range is
// the slant range |d| of the state; a track started from polar points lies in the radar's
// horizontal plane (cartesian_radar_state.hpp), where it equals the ground range.
// Near the vertical of the radar (horizontal range below kZenithFraction r, only off the plane) the
// azimuth row is dropped as in ekf_radar_update; there is no curvature conditioning (its derivation
// is for [r, az, el]).
// ekf_polar_linearise: the update up to S (nu, S's lower triangle, P H'), changing nothing, as
// ekf_radar_linearise.
template <int N, int M>
EkfOutcome ekf_polar_linearise(const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& P,
                               const int idx[6], const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured,
                               EkfInnovation<M>& out, Eigen::Matrix<double, N, M>& PHt) {
  static_assert(M == 2 || M == 3);
  constexpr int MS = M + 1;  // the spherical model with elevation: [r, az, el(, rdot)]
  using MatM = Eigen::Matrix<double, M, M>;
  out.azimuth_dropped = out.azimuth_deweighted = false;
  const Vec3 d = frame_to_sensor(m, Vec3(x(idx[0]), x(idx[1]), x(idx[2])) - m.sensor_position);
  const Vec3 v = frame_to_sensor(m, Vec3(x(idx[3]), x(idx[4]), x(idx[5])));
  SphericalJacobian<MS> Js;
  SphericalVec<MS> hs;
  const SphericalSingularity sing = spherical_measurement_with_jacobian<MS>(d, v, m.azimuth, hs, Js);
  if (sing == SphericalSingularity::AtSensor) return EkfOutcome::AtSensor;
  // Rows r, az (, rdot) of the spherical model: measurement row k is spherical row row_of[k].
  constexpr int row_of[3] = {0, 1, 3};
  Eigen::Matrix<double, M, 6> J;
  Eigen::Matrix<double, M, 1> h;
  for (int k = 0; k < M; ++k) {
    J.row(k) = Js.row(row_of[k]);
    h(k) = hs(row_of[k]);
  }
  Eigen::Matrix<double, M, 1> nu = m.value.template head<M>() - h;
  nu(1) = wrap_angle(nu(1));
  MatM R = R_measured;
  if (sing == SphericalSingularity::Zenith) {  // an infinitely uncertain azimuth, as in condition_near_zenith
    out.azimuth_dropped = true;
    J.row(1).setZero();
    drop_azimuth_noise<M>(nu, R);
  }
  radar_gain_terms<N, M>(P, idx, m, M == 3 ? 2 : -1, J, R, PHt, out.S);
  out.nu = nu;
  return EkfOutcome::Used;
}

template <int N, int M>
EkfOutcome ekf_polar_update(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P, const int idx[6],
                            const Measurement& m, const Eigen::Matrix<double, M, M>& R_measured, EkfInnovation<M>& out) {
  Eigen::Matrix<double, N, M> PHt;
  if (ekf_polar_linearise<N, M>(x, P, idx, m, R_measured, out, PHt) == EkfOutcome::AtSensor) return EkfOutcome::AtSensor;
  if (joseph_update_cross<N, M>(x, P, out.nu, PHt, out.S, out.nis, nullptr, &out.det_S)) return EkfOutcome::Used;
  return EkfOutcome::NotPositiveDefinite;
}

}  // namespace trackflow::cartesian_filter
