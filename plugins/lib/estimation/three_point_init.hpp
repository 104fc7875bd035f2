// Purpose: finite-difference track initialisation from three positions and the paper-000 initial covariance (§IV.2.1) in its symmetric form.
#pragma once

#include <Eigen/Core>

namespace trackflow::cartesian_filter {

// Rows: position, velocity and acceleration at t3 as linear combinations of the positions
// measured at t1, t2, t3 (T1 = t2 - t1, T2 = t3 - t2):
//   p = z3,  v = (z3 - z2) / T2,  a = 2 [(z3 - z2)/T2 - (z2 - z1)/T1] / (T1 + T2).
// For T1 = T2 = T: v = (z3 - z2)/T, a = (z3 - 2 z2 + z1)/T^2, the differencing behind paper 000's P0.
inline Eigen::Matrix3d three_point_differences(double T1, double T2) {
  Eigen::Matrix3d A;
  A << 0.0, 0.0, 1.0,
       0.0, -1.0 / T2, 1.0 / T2,
       2.0 / (T1 * (T1 + T2)), -2.0 / (T1 * T2), 2.0 / (T2 * (T1 + T2));
  return A;
}

// Covariance of [p, v, a] when the three positions are independent with variance sigma2:
// sigma2 A A'. For T1 = T2 = T it is
//   [[s2, s2/T, s2/T^2], [s2/T, 2 s2/T^2, 3 s2/T^3], [s2/T^2, 3 s2/T^3, 6 s2/T^4]],
// paper 000's P0 except that the paper prints 2 s2/T^2 in the (3,1) corner (not symmetric);
// cov(z3, (z3 - 2 z2 + z1)/T^2) = s2/T^2, as in its own (1,3) entry. Positive definite because A
// is invertible.
inline Eigen::Matrix3d paper000_axis_covariance(double sigma2, double T1, double T2) {
  const Eigen::Matrix3d A = three_point_differences(T1, T2);
  const Eigen::Matrix3d P = sigma2 * A * A.transpose();
  return 0.5 * (P + P.transpose());
}

}  // namespace trackflow::cartesian_filter
