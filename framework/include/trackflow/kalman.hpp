// Purpose: fixed-size Kalman measurement updates in Joseph form, shared by the filters: the dense textbook form, and the same update from P H' and S that never forms H or an N x N x N product.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>

namespace trackflow {

// Linear update x += K nu, P = (I-KH) P (I-KH)' + K R K' (Joseph form: stays symmetric
// positive semi-definite under rounding, unlike P - K S K'). Returns false and leaves x, P
// untouched if S is not positive definite. nu is the innovation z - Hx (angles already wrapped).
// The filters use joseph_update_cross below, which gives the same result without N x N x N
// products; this dense form is the reference it is tested against.
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

// The same Joseph-form update given the cross covariance PHt = P H' (N x M) and the innovation
// covariance S = H P H' + R (M x M, symmetric), so that H itself is never needed: the filters
// form PHt and S from the non-zero columns of H only (a selection of position states in
// filter.kalman, the 3 or 6 position/velocity columns of the radar Jacobian in filter.ekf,
// L G for the UKF's statistically linearised H). With K = PHt S^-1 (through the Cholesky factor
// S = L L'),
//   P <- P - K PHt' + (K S - PHt) K'
// is the Joseph form (I-KH) P (I-KH)' + K R K' identically, for every K: expanding the Joseph
// form gives P - K PHt' - PHt K' + K S K', and (K S - PHt) K' = K S K' - PHt K'. So it keeps
// what makes the Joseph form the stable one: with K = K* + dK (the optimal gain plus the
// rounding of its computation) the result is P* + dK S dK' — the gain's error enters to second
// order and as a positive semi-definite term — whereas P - K S K' takes it to first order. The
// correction (K S - PHt) vanishes in exact arithmetic; computing it costs N M^2 multiplications
// and no N x N x N product. Evaluated on the upper triangle and mirrored: symmetric by
// construction. Multiplications: N M^2 (K = PHt S^-1) + N M^2 (K S) + N(N+1) M (P) + O(M^3),
// e.g. about 700 for N = 9, M = 4 against about 2900 for the dense form.
// Returns false (x, P untouched) when S is not positive definite; S is returned symmetric.
// K, when given, receives the gain; det_S, when given, det S (the product of the Cholesky pivots:
// an IMM's likelihood needs it, and the factor is at hand here).
template <int N, int M>
bool joseph_update_cross(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P,
                         const Eigen::Matrix<double, M, 1>& nu, const Eigen::Matrix<double, N, M>& PHt,
                         Eigen::Matrix<double, M, M>& S, double& nis, Eigen::Matrix<double, N, M>* K_out = nullptr,
                         double* det_S = nullptr) {
  // Cholesky factor of S (lower), with 1 / diagonal.
  double L[M][M] = {}, inv[M];
  double det = 1.0;
  for (int j = 0; j < M; ++j) {
    double d = S(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;  // also refuses NaN
    det *= d;
    L[j][j] = std::sqrt(d);
    inv[j] = 1.0 / L[j][j];
    for (int i = j + 1; i < M; ++i) {
      double s = S(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s * inv[j];
    }
  }
  for (int i = 0; i < M; ++i)
    for (int j = i + 1; j < M; ++j) S(i, j) = S(j, i);
  // S^-1 = L^-T L^-1 (M is at most 4: cheaper than N triangular solves), then K = PHt S^-1.
  double Li[M][M] = {}, Si[M][M];
  for (int j = 0; j < M; ++j) {
    Li[j][j] = inv[j];
    for (int i = j + 1; i < M; ++i) {
      double s = 0.0;
      for (int k = j; k < i; ++k) s -= L[i][k] * Li[k][j];
      Li[i][j] = s * inv[i];
    }
  }
  for (int i = 0; i < M; ++i)
    for (int j = 0; j < M; ++j) {
      double s = 0.0;
      for (int k = i > j ? i : j; k < M; ++k) s += Li[k][i] * Li[k][j];
      Si[i][j] = s;
    }
  // K = PHt S^-1 and G = K S - PHt (zero in exact arithmetic: the Joseph correction), as columns
  // ([column][row]) so the loops run over the N rows, lane by lane.
  alignas(16) double Kc[M][N], Gc[M][N];
  for (int m = 0; m < M; ++m) {
    for (int r = 0; r < N; ++r) Kc[m][r] = PHt(r, 0) * Si[0][m];
    for (int k = 1; k < M; ++k)
      for (int r = 0; r < N; ++r) Kc[m][r] += PHt(r, k) * Si[k][m];
  }
  for (int m = 0; m < M; ++m) {
    for (int r = 0; r < N; ++r) Gc[m][r] = -PHt(r, m);
    for (int k = 0; k < M; ++k)
      for (int r = 0; r < N; ++r) Gc[m][r] += Kc[k][r] * S(k, m);
  }
  // P += A B' with A = [G, -K], B = [K, PHt] (N x 2M), i.e. G K' - K PHt', on the upper triangle.
  // Each entry is a dot product of 2M terms, taken two at a time in a vector of two doubles
  // (GCC/Clang vector extension; the compiler may not reorder a plain sum, so it would not
  // vectorise it), then mirrored.
  typedef double Pair __attribute__((vector_size(16)));
  Pair A[N][M], B[N][M];  // 2M doubles = M pairs per row
  for (int r = 0; r < N; ++r) {
    double a[2 * M], b[2 * M];
    for (int m = 0; m < M; ++m) {
      a[m] = Gc[m][r];
      a[M + m] = -Kc[m][r];
      b[m] = Kc[m][r];
      b[M + m] = PHt(r, m);
    }
    for (int h = 0; h < M; ++h) {
      A[r][h] = Pair{a[2 * h], a[2 * h + 1]};
      B[r][h] = Pair{b[2 * h], b[2 * h + 1]};
    }
  }
  for (int j = 0; j < N; ++j)
    for (int i = 0; i <= j; ++i) {
      Pair acc = A[i][0] * B[j][0];
      for (int h = 1; h < M; ++h) acc += A[i][h] * B[j][h];
      P(i, j) += acc[0] + acc[1];
      P(j, i) = P(i, j);
    }
  // NIS = |L^-1 nu|^2; x += K nu.
  nis = 0.0;
  for (int m = 0; m < M; ++m) {
    double s = 0.0;
    for (int k = 0; k <= m; ++k) s += Li[m][k] * nu(k);
    nis += s * s;
  }
  for (int r = 0; r < N; ++r) {
    double s = x(r);
    for (int m = 0; m < M; ++m) s += Kc[m][r] * nu(m);
    x(r) = s;
  }
  if (K_out)
    for (int r = 0; r < N; ++r)
      for (int m = 0; m < M; ++m) (*K_out)(r, m) = Kc[m][r];
  if (det_S) *det_S = det;
  return true;
}

}  // namespace trackflow
