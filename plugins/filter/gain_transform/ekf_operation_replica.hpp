// Purpose: scalar-generic replicas of the full-EKF step (filter.ekf's Singer path, and a lean H-sparse EKF) so the multiplication counts can be instrumented (test and benchmark only).
#pragma once

#include "gain_transform_core.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>

namespace trackflow::gain_transform::replica {

template <class S, int R, int C>
using Mat = Eigen::Matrix<S, R, C>;

// filter.ekf's prediction (plugins/lib/estimation/cartesian_radar_estimator.hpp, predict(); the update is
// ekf_filter.cpp's): x_a = A x_a per axis (27 multiplications),
// P_ab = A P_ab A' for all nine axis blocks (9 x 54), noise q_a^2 Q1 on the diagonal blocks
// (3 x 10), then P = (P + P')/2 (81): 597 for the covariance.
template <class S>
void ekf_predict_state(Mat<S, 9, 1>& x, const Mat<S, 3, 3>& A) {
  for (int a = 0; a < 3; ++a) {
    const Mat<S, 3, 1> xa = A * x.template segment<3>(a * 3);
    x.template segment<3>(a * 3) = xa;
  }
}
template <class S>
void ekf_predict_covariance(Mat<S, 9, 9>& P, const Mat<S, 3, 3>& A, const Mat<S, 3, 3>& Q1, const S q[3]) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const Mat<S, 3, 3> Pab = A * P.template block<3, 3>(a * 3, b * 3) * A.transpose();
      P.template block<3, 3>(a * 3, b * 3) = Pab;
    }
  for (int a = 0; a < 3; ++a) P.template block<3, 3>(a * 3, a * 3) += (q[a] * q[a]) * Q1;
  P = (S(0.5) * (P + P.transpose())).eval();
}

// A lean covariance prediction using the structure of the Singer F = [[1, f01, f02], [0, 1, f12],
// [0, 0, f22]] per axis and the symmetry of P: the three diagonal blocks with predict_axis (16 +
// 6 for the noise, as the gain-transform filter does per LOS axis), the three upper off-diagonal
// blocks as a general F B F' (12 for F B, 12 for (F B) F'): 3 x 22 + 3 x 24 = 138
// multiplications, one sigma_m for all axes.
template <class S>
void lean_predict_covariance(Mat<S, 9, 9>& P, const SingerAxis<S>& m, const S& sigma2) {
  for (int a = 0; a < 3; ++a) {
    AxisCov<S> B{P(3 * a, 3 * a),     P(3 * a, 3 * a + 1),     P(3 * a, 3 * a + 2),
                 P(3 * a + 1, 3 * a + 1), P(3 * a + 1, 3 * a + 2), P(3 * a + 2, 3 * a + 2)};
    predict_axis(B, m, sigma2);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) P(3 * a + i, 3 * a + j) = B.at(i, j);
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      const Mat<S, 3, 3> B = P.template block<3, 3>(3 * a, 3 * b);
      Mat<S, 3, 3> FB, out;
      for (int j = 0; j < 3; ++j) {
        FB(0, j) = B(0, j) + m.f01 * B(1, j) + m.f02 * B(2, j);
        FB(1, j) = B(1, j) + m.f12 * B(2, j);
        FB(2, j) = m.f22 * B(2, j);
      }
      for (int i = 0; i < 3; ++i) {
        out(i, 0) = FB(i, 0) + m.f01 * FB(i, 1) + m.f02 * FB(i, 2);
        out(i, 1) = FB(i, 1) + m.f12 * FB(i, 2);
        out(i, 2) = m.f22 * FB(i, 2);
      }
      P.template block<3, 3>(3 * a, 3 * b) = out;
      P.template block<3, 3>(3 * b, 3 * a) = out.transpose();
    }
}

// The arithmetic of spherical_measurement_jacobian<3> (spherical_measurement.hpp), north_clockwise,
// scattered into the 3x9 H as filter.ekf does.
template <class S>
void ekf_jacobian(const S d[3], Mat<S, 3, 9>& H) {
  using std::hypot;
  H.setZero();
  const S rho = hypot(d[0], d[1]);
  const S r = hypot(rho, d[2]);
  const S ux = d[0] / rho, uy = d[1] / rho;
  const S inv_rho = S(1.0) / rho;
  const S r2 = r * r;
  for (int a = 0; a < 3; ++a) H(0, 3 * a) = d[a] / r;
  H(1, 0) = uy * inv_rho;
  H(1, 3) = -ux * inv_rho;
  H(2, 0) = -ux * d[2] / r2;
  H(2, 3) = -uy * d[2] / r2;
  H(2, 6) = rho / r2;
}

// The arithmetic of ekf::angle_curvature_variance (plugins/lib/estimation/zenith_linearisation.hpp).
template <class S>
void ekf_curvature(const S d[3], const S Ph[2][2], S& azimuth, S& elevation) {
  using std::hypot;
  const S rho = hypot(d[0], d[1]);
  const S r2 = rho * rho + d[2] * d[2];
  const S par[2] = {d[0] / rho, d[1] / rho};
  const S perp[2] = {-par[1], par[0]};
  auto quad = [&](const S* u, const S* v) {
    return u[0] * (Ph[0][0] * v[0] + Ph[0][1] * v[1]) + u[1] * (Ph[1][0] * v[0] + Ph[1][1] * v[1]);
  };
  const S a = quad(par, par), b = quad(perp, perp), c = quad(par, perp);
  const S rho2 = rho * rho;
  azimuth = (a * b + c * c) / (rho2 * rho2);
  const S k = d[2] * b / (r2 * rho);
  elevation = S(0.5) * k * k;
}

// trackflow::joseph_update (kalman.hpp) split in its three phases, expression for expression.
template <class S>
struct JosephGain {
  Mat<S, 9, 3> PHt, K;
  Mat<S, 3, 3> Sinn;
  Eigen::LLT<Mat<S, 3, 3>> llt;
};
template <class S>
void ekf_gain(const Mat<S, 9, 9>& P, const Mat<S, 3, 9>& H, const Mat<S, 3, 3>& R, JosephGain<S>& g) {
  g.PHt = P * H.transpose();
  g.Sinn.noalias() = H * g.PHt;
  g.Sinn += R;
  g.llt.compute(g.Sinn);
  g.K = g.llt.solve(g.PHt.transpose()).transpose();
}
template <class S>
void ekf_joseph_covariance(Mat<S, 9, 9>& P, const Mat<S, 3, 9>& H, const Mat<S, 3, 3>& R, const Mat<S, 9, 3>& K) {
  Mat<S, 9, 9> IKH = -K * H;
  IKH.diagonal().array() += S(1.0);
  const Mat<S, 9, 9> P1 = IKH * P * IKH.transpose() + K * R * K.transpose();
  P = S(0.5) * (P1 + P1.transpose());
}
template <class S>
void ekf_state(Mat<S, 9, 1>& x, const Mat<S, 3, 1>& nu, const JosephGain<S>& g, S& nis) {
  nis = nu.dot(g.llt.solve(nu));
  x.noalias() += g.K * nu;
}

// A lean EKF gain computation, the textbook update written for H = [G 0 0] (only the position
// columns are non-zero) and symmetric S and P:
//   PHt = P(:, pos) G'  (81),  S = G PHt(pos, :) + R, upper triangle (18),
//   S^-1 by cofactors (21 and 1 division),  K = PHt S^-1 (81),
//   P -= K PHt', upper triangle (45 entries x 3 = 135).
// G = Lambda^-1 D' is taken from the LOS frame (6 multiplications, 2 divisions).
template <class S>
void lean_ekf_gain(Mat<S, 9, 9>& P, const S u[3][3], const S scale[3], const Mat<S, 3, 3>& R, Mat<S, 9, 3>& K,
                   Mat<S, 3, 3>& Sinn) {
  S G[3][3];
  const S inv1 = S(1.0) / scale[1], inv2 = S(1.0) / scale[2];
  for (int a = 0; a < 3; ++a) {
    G[0][a] = u[0][a];
    G[1][a] = u[1][a] * inv1;
    G[2][a] = u[2][a] * inv2;
  }
  Mat<S, 9, 3> PHt;
  for (int r = 0; r < 9; ++r)
    for (int m = 0; m < 3; ++m) PHt(r, m) = P(r, 0) * G[m][0] + P(r, 3) * G[m][1] + P(r, 6) * G[m][2];
  for (int m = 0; m < 3; ++m)
    for (int n = m; n < 3; ++n)
      Sinn(m, n) = Sinn(n, m) = G[m][0] * PHt(0, n) + G[m][1] * PHt(3, n) + G[m][2] * PHt(6, n) + R(m, n);
  const S c00 = Sinn(1, 1) * Sinn(2, 2) - Sinn(1, 2) * Sinn(1, 2);
  const S c01 = Sinn(0, 2) * Sinn(1, 2) - Sinn(0, 1) * Sinn(2, 2);
  const S c02 = Sinn(0, 1) * Sinn(1, 2) - Sinn(0, 2) * Sinn(1, 1);
  const S c11 = Sinn(0, 0) * Sinn(2, 2) - Sinn(0, 2) * Sinn(0, 2);
  const S c12 = Sinn(0, 1) * Sinn(0, 2) - Sinn(0, 0) * Sinn(1, 2);
  const S c22 = Sinn(0, 0) * Sinn(1, 1) - Sinn(0, 1) * Sinn(0, 1);
  const S inv_det = S(1.0) / (Sinn(0, 0) * c00 + Sinn(0, 1) * c01 + Sinn(0, 2) * c02);
  const S Si[3][3] = {{c00 * inv_det, c01 * inv_det, c02 * inv_det},
                      {S(0.0), c11 * inv_det, c12 * inv_det},
                      {S(0.0), S(0.0), c22 * inv_det}};
  auto si = [&](int m, int n) { return m <= n ? Si[m][n] : Si[n][m]; };
  for (int r = 0; r < 9; ++r)
    for (int n = 0; n < 3; ++n) K(r, n) = PHt(r, 0) * si(0, n) + PHt(r, 1) * si(1, n) + PHt(r, 2) * si(2, n);
  for (int r = 0; r < 9; ++r)
    for (int c = r; c < 9; ++c)
      P(r, c) = P(c, r) = P(r, c) - (K(r, 0) * PHt(c, 0) + K(r, 1) * PHt(c, 1) + K(r, 2) * PHt(c, 2));
}

}  // namespace trackflow::gain_transform::replica
