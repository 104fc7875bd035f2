// Purpose: track-to-track fusion of two Gaussian estimates: covariance intersection (weight by the trace or the determinant) and information matrix fusion that removes the common prior; fixed-size, allocation-free.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <cmath>

namespace trackflow::fusion {

enum class CiCriterion { Trace, Determinant };

// The information form of a covariance: Y = P^-1 (false when P is not positive definite).
template <int N>
bool information(const Eigen::Matrix<double, N, N>& P, Eigen::Matrix<double, N, N>& Y) {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(P);
  if (llt.info() != Eigen::Success) return false;
  Y = llt.solve(Eigen::Matrix<double, N, N>::Identity());
  Y = 0.5 * (Y + Y.transpose());
  return Y.allFinite();
}

// Covariance intersection (Julier & Uhlmann 1997):
//   P^-1 = w P1^-1 + (1 - w) P2^-1,   x = P (w P1^-1 x1 + (1 - w) P2^-1 x2),
// consistent whatever the (unknown) correlation of the two errors, with w in [0, 1] minimising
// tr P (Trace) or det P (Determinant). With Y2 = L L' and the eigen-decomposition
// L^-1 Y1 L^-T = V diag(lambda) V', the combination is L V diag(1 + w (lambda_i - 1)) V' L', so
//   det P = det(Y2)^-1 prod_i (1 + w (lambda_i - 1))^-1,   tr P = sum_i c_i / (1 + w (lambda_i - 1))
// with c_i the squared norm of column i of L^-T V: one eigen-decomposition per fusion, then a
// scalar search. Both criteria are convex in w: bisection on the sign of the derivative over
// [0, 1] (fixed iterations: the same w on every machine), the ends included.
template <int N>
struct CiResult {
  Eigen::Matrix<double, N, 1> x;
  Eigen::Matrix<double, N, N> P;
  double w = 0.5;  // weight of the first estimate
};

template <int N>
bool covariance_intersection(const Eigen::Matrix<double, N, 1>& x1, const Eigen::Matrix<double, N, N>& P1,
                             const Eigen::Matrix<double, N, 1>& x2, const Eigen::Matrix<double, N, N>& P2,
                             CiCriterion criterion, CiResult<N>& out) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  Mat Y1, Y2;
  if (!information<N>(P1, Y1) || !information<N>(P2, Y2)) return false;
  const Eigen::LLT<Mat> llt2(Y2);
  if (llt2.info() != Eigen::Success) return false;
  const Mat L = llt2.matrixL();
  // M = L^-1 Y1 L^-T (symmetric): two triangular solves.
  Mat M = L.template triangularView<Eigen::Lower>().solve(Y1);
  M = L.template triangularView<Eigen::Lower>().solve(M.transpose()).eval();
  M = 0.5 * (M + M.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat> eig(M);
  if (eig.info() != Eigen::Success) return false;
  const Vec lambda = eig.eigenvalues().cwiseMax(0.0);  // Y1 >= 0: rounding only below 0
  // W = L^-T V: P = W diag(1 / d) W'.
  const Mat W = L.transpose().template triangularView<Eigen::Upper>().solve(eig.eigenvectors());
  const Vec c = W.colwise().squaredNorm().transpose();
  // The criterion's derivative in w (increasing: both criteria are convex), by bisection: the
  // minimum is where it changes sign, or an end of [0, 1] where it does not. The derivative, not
  // the criterion, is searched: near the minimum the criterion is flat to O(dw^2), which would
  // limit w to ~1e-8; the derivative resolves it to the last bits.
  auto slope = [&](double w) {
    double s = 0.0;
    for (int i = 0; i < N; ++i) {
      const double d = 1.0 + w * (lambda(i) - 1.0), g = lambda(i) - 1.0;
      s += criterion == CiCriterion::Trace ? -c(i) * g / (d * d) : -g / d;
    }
    return s;
  };
  double w;
  if (slope(0.0) >= 0.0) {
    w = 0.0;
  } else if (slope(1.0) <= 0.0) {
    w = 1.0;
  } else {
    double a = 0.0, b = 1.0;
    for (int it = 0; it < 60; ++it) {  // 2^-60: below the spacing of doubles near 1
      const double m = 0.5 * (a + b);
      (slope(m) < 0.0 ? a : b) = m;
    }
    w = 0.5 * (a + b);
  }
  Vec inv_d;
  for (int i = 0; i < N; ++i) {
    const double d = 1.0 + w * (lambda(i) - 1.0);
    if (!(d > 0.0)) return false;
    inv_d(i) = 1.0 / d;
  }
  out.w = w;
  out.P = W * inv_d.asDiagonal() * W.transpose();
  out.P = 0.5 * (out.P + out.P.transpose());
  out.x = out.P * (w * (Y1 * x1) + (1.0 - w) * (Y2 * x2));
  return out.P.allFinite() && out.x.allFinite();
}

// The fusion that takes the two errors as independent: P^-1 = P1^-1 + P2^-1, x = P (P1^-1 x1 +
// P2^-1 x2). Optimal only without cross-covariance; the local tracks of one target share the
// process noise (Bar-Shalom & Campo 1986), so this is overconfident: a baseline.
template <int N>
bool independent_fusion(const Eigen::Matrix<double, N, 1>& x1, const Eigen::Matrix<double, N, N>& P1,
                        const Eigen::Matrix<double, N, 1>& x2, const Eigen::Matrix<double, N, N>& P2, CiResult<N>& out) {
  using Mat = Eigen::Matrix<double, N, N>;
  Mat Y1, Y2;
  if (!information<N>(P1, Y1) || !information<N>(P2, Y2)) return false;
  const Eigen::LLT<Mat> llt(Y1 + Y2);
  if (llt.info() != Eigen::Success) return false;
  out.P = llt.solve(Mat::Identity());
  out.P = 0.5 * (out.P + out.P.transpose());
  out.x = llt.solve(Y1 * x1 + Y2 * x2);
  out.w = 0.5;
  return out.P.allFinite() && out.x.allFinite();
}

// Information matrix fusion (Chong, Mori & Chang 1990; exact for full-rate communication, Tian &
// Bar-Shalom 2009): the fused track, predicted to the time of a local update, takes only the
// information that update added,
//   Yf+ = Yf- + (Yi(k|k) - Yi(k|k-1)),   yf+ = yf- + (yi(k|k) - yi(k|k-1)),   y = Y x,
// where Yi(k|k-1) is the local track's own prediction from its previous estimate. The prior every
// local track shares with the fused one (its process noise) is thus counted once. A local track
// with no previous estimate (its first) adds all its information. False when the fused
// information is not positive definite (the caller restarts the fused track).
template <int N>
bool information_fusion(Eigen::Matrix<double, N, 1>& xf, Eigen::Matrix<double, N, N>& Pf, bool fused_has_prior,
                        const Eigen::Matrix<double, N, 1>& xi, const Eigen::Matrix<double, N, N>& Pi,
                        bool local_has_prior, const Eigen::Matrix<double, N, 1>& xi_pred,
                        const Eigen::Matrix<double, N, N>& Pi_pred) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  Mat Y = Mat::Zero(), Yi, Yp;
  Vec y = Vec::Zero();
  if (fused_has_prior) {
    if (!information<N>(Pf, Y)) return false;
    y = Y * xf;
  }
  if (!information<N>(Pi, Yi)) return false;
  Y += Yi;
  y += Yi * xi;
  if (local_has_prior) {
    if (!information<N>(Pi_pred, Yp)) return false;
    Y -= Yp;
    y -= Yp * xi_pred;
  }
  Y = 0.5 * (Y + Y.transpose());
  const Eigen::LLT<Mat> llt(Y);
  if (llt.info() != Eigen::Success) return false;
  Pf = llt.solve(Mat::Identity());
  Pf = 0.5 * (Pf + Pf.transpose());
  xf = llt.solve(y);
  return Pf.allFinite() && xf.allFinite();
}

}  // namespace trackflow::fusion
