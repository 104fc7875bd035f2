// Purpose: fixed-size Kalman measurement update in Joseph form, shared by the linear filters.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace trackflow {

// Linear update x += K nu, P = (I-KH) P (I-KH)' + K R K' (Joseph form: stays symmetric
// positive semi-definite under rounding, unlike P - K S K'). Returns false and leaves x, P
// untouched if S is not positive definite. nu is the innovation z - Hx (angles already wrapped).
template <int N, int M>
bool joseph_update(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P,
                   const Eigen::Matrix<double, M, 1>& nu, const Eigen::Matrix<double, M, N>& H,
                   const Eigen::Matrix<double, M, M>& R, Eigen::Matrix<double, M, M>& S, double& nis) {
  const Eigen::Matrix<double, N, M> PHt = P * H.transpose();
  S.noalias() = H * PHt;
  S += R;
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  if (llt.info() != Eigen::Success) return false;
  // K = P H' S^-1 computed as (S^-1 H P)' to use the Cholesky factor.
  const Eigen::Matrix<double, N, M> K = llt.solve(PHt.transpose()).transpose();
  nis = nu.dot(llt.solve(nu));
  x.noalias() += K * nu;
  Eigen::Matrix<double, N, N> IKH = -K * H;
  IKH.diagonal().array() += 1.0;
  const Eigen::Matrix<double, N, N> P1 = IKH * P * IKH.transpose() + K * R * K.transpose();
  P = 0.5 * (P1 + P1.transpose());
  return true;
}

}  // namespace trackflow
