// Purpose: the zenith guard shared by filter.ekf (and filter.imm's EKF modes) and filter.ukf: the predicted horizontal covariance in the sensor's axes, the test that the zenith is within 3 sigma of the prediction, and the dropped azimuth's measurement noise.
#pragma once

#include "zenith_linearisation.hpp"

#include <trackflow/items.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Core>

#include <cmath>

namespace trackflow::cartesian_filter {

// The 2 x 2 horizontal block of the predicted position covariance, in the sensor's own axes
// (a tilted sensor: Measurement::sensor_axes); idx: the state indices of [x y z vx vy vz].
template <int N>
Eigen::Matrix2d horizontal_covariance(const Eigen::Matrix<double, N, N>& P, const int idx[6], const Measurement& m) {
  Eigen::Matrix2d Ph;
  Ph << P(idx[0], idx[0]), P(idx[0], idx[1]), P(idx[1], idx[0]), P(idx[1], idx[1]);
  if (!m.sensor_level) {
    Mat3 Pp;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Pp(i, j) = P(idx[i], idx[j]);
    Ph = (m.sensor_axes.transpose() * Pp * m.sensor_axes).template topLeftCorner<2, 2>();
  }
  return Ph;
}

// Whether the azimuth must not be used at all: the predicted position d (sensor axes) is
// straight overhead (horizontal range below kZenithFraction r, SphericalSingularity::Zenith) or
// the zenith lies within kZenithSigmas standard deviations of it (zenith_linearisation.hpp): the
// azimuth may then flip by pi between the prediction and the truth, which neither a Taylor
// expansion (the EKF) nor sigma points straddling the zenith (the UKF, whose azimuths then
// average to nothing meaningful) can represent.
// The test itself is ekf::angle_curvature_variance's (one test for both filters).
inline bool azimuth_unusable(const Vec3& d, const Eigen::Matrix2d& Ph) {
  const double r = d.norm();
  return std::hypot(d.x(), d.y()) < kZenithFraction * r ||
         ekf::angle_curvature_variance(d, Ph, kZenithFraction * r).azimuth_unusable;
}

// The dropped azimuth (row/column 1 of [r, az, el(, rdot)]): zero innovation and R decorrelated
// with its own variance kept (1 if it had none), i.e. an infinitely uncertain azimuth once the
// caller zeroes its row of H (J's row 1 in the EKF, G's column 1 in the UKF): range, elevation and
// range rate still update.
template <int M>
void drop_azimuth_noise(Eigen::Matrix<double, M, 1>& nu, Eigen::Matrix<double, M, M>& R) {
  const double raz = R(1, 1);
  nu(1) = 0.0;
  R.row(1).setZero();
  R.col(1).setZero();
  R(1, 1) = raz > 0.0 ? raz : 1.0;
}

}  // namespace trackflow::cartesian_filter
