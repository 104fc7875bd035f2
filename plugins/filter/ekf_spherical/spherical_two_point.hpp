// Purpose: two-point initialisation of the spherical CA state from two [r, az, el(, rdot)] measurements, with its linearised covariance.
#pragma once

#include "spherical_ca_model.hpp"

#include <trackflow/geometry.hpp>

namespace trackflow::ekf_spherical {

using Meas4 = Eigen::Matrix<double, 4, 1>;
using Cov4 = Eigen::Matrix<double, 4, 4>;

// z = [r, az, el, rdot] (SDK order; rdot and its row/column of R unused unless use_rate) at t1 < t2,
// T = t2 − t1. Position states from the second point; v_r = (r2 − r1)/T or rdot2;
// v_h = r2 cos φ2 (θ2 − θ1)/T with the azimuth difference wrapped; v_v = r2 (φ2 − φ1)/T; the v̇
// states 0 with variance sigma_accel². P = J1 R1 J1' + J2 R2 J2' (first order in the noise).
inline void two_point_state(const Meas4& z1, const Cov4& R1, const Meas4& z2, const Cov4& R2, double T,
                            bool use_rate, double sigma_accel, State& x, Matrix& P) {
  const double r2 = z2(0), th2 = z2(1), ph2 = z2(2);
  const double dth = wrap_angle(z2(1) - z1(1)), dph = z2(2) - z1(2);
  const double c2 = std::cos(ph2), s2 = std::sin(ph2);
  x.setZero();
  x(kR) = r2;
  x(kVr) = use_rate ? z2(3) : (r2 - z1(0)) / T;
  x(kTheta) = wrap_angle(th2);
  x(kVh) = r2 * c2 * dth / T;
  x(kPhi) = ph2;
  x(kVv) = r2 * dph / T;

  Eigen::Matrix<double, kDim, 4> J1 = Eigen::Matrix<double, kDim, 4>::Zero(), J2 = J1;
  J2(kR, 0) = 1.0;
  if (use_rate) {
    J2(kVr, 3) = 1.0;
  } else {
    J2(kVr, 0) = 1.0 / T;
    J1(kVr, 0) = -1.0 / T;
  }
  J2(kTheta, 1) = 1.0;
  J2(kVh, 0) = c2 * dth / T;
  J2(kVh, 1) = r2 * c2 / T;
  J2(kVh, 2) = -r2 * s2 * dth / T;
  J1(kVh, 1) = -r2 * c2 / T;
  J2(kPhi, 2) = 1.0;
  J2(kVv, 0) = dph / T;
  J2(kVv, 2) = r2 / T;
  J1(kVv, 2) = -r2 / T;
  P = J1 * R1 * J1.transpose() + J2 * R2 * J2.transpose();
  const double sa2 = sigma_accel * sigma_accel;
  P(kAr, kAr) = P(kAh, kAh) = P(kAv, kAv) = sa2;
  P = (0.5 * (P + P.transpose())).eval();
}

}  // namespace trackflow::ekf_spherical
