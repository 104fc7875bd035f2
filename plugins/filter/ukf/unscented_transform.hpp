// Purpose: the scaled unscented transform (Julier 2002; Wan & van der Merwe 2000) of the spherical radar measurement: weights, a guarded Cholesky factor, and the angle-aware predicted measurement moments.
#pragma once

#include <trackflow/geometry.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <array>
#include <cmath>

namespace trackflow::ukf {

// Weights of the 2n+1 sigma points x, x ± c L_j (L L' = P):
//   lambda = alpha^2 (n + kappa) - n,   c^2 = n + lambda,
//   W0m = lambda / (n + lambda),   W0c = W0m + 1 - alpha^2 + beta,   Wi = 1 / (2 (n + lambda)).
struct ScaledWeights {
  int n = 0;
  double lambda = 0.0, spread = 0.0;  // spread = c = sqrt(n + lambda)
  double mean0 = 0.0, cov0 = 0.0, other = 0.0;

  static ScaledWeights make(int n, double alpha, double beta, double kappa) {
    ScaledWeights w;
    w.n = n;
    w.lambda = alpha * alpha * (n + kappa) - n;
    const double nl = n + w.lambda;  // = alpha^2 (n + kappa) > 0, checked by the caller
    w.spread = std::sqrt(nl);
    w.mean0 = w.lambda / nl;
    w.cov0 = w.mean0 + 1.0 - alpha * alpha + beta;
    w.other = 0.5 / nl;
    return w;
  }
};

// Lower Cholesky factor L L' = A from A's lower triangle (as Eigen::LLT reads it); the upper
// triangle of L is zero (written column by column: no separate pass over all of L). False when a pivot is not positive (or NaN). Plain loops over the fixed
// size: for a 9 x 9 about 85 ns against 210 ns for Eigen::LLT and 140 ns for a column-oriented
// variant (measured on the project's machine, g++ 12 -O3).
template <int N>
bool cholesky_lower(const Eigen::Matrix<double, N, N>& A, Eigen::Matrix<double, N, N>& L) {
  for (int j = 0; j < N; ++j) {
    for (int i = 0; i < j; ++i) L(i, j) = 0.0;  // the upper triangle (column j above the diagonal)
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > 0.0)) return false;  // L is then only partly written
    const double ljj = std::sqrt(d), inv = 1.0 / ljj;
    L(j, j) = ljj;
    for (int i = j + 1; i < N; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s * inv;
    }
  }
  return true;
}

// Cholesky factor L of P for the sigma points. If P is not numerically positive definite it is
// symmetrised and a growing multiple of its largest variance (1e-12 ... 1e-4) is added to the
// diagonal; P itself is replaced by the matrix that was factored, so the sigma points and the
// update describe the same covariance. Returns the jitter added (0: none) or -1 if P could not
// be factored (non-finite, or indefinite beyond 1e-4 of its scale).
template <int N>
double guarded_cholesky(Eigen::Matrix<double, N, N>& P, Eigen::Matrix<double, N, N>& L) {
  // Not finite: a NaN or an infinity anywhere makes the sum NaN or infinite (as would entries
  // summing beyond 1.8e308, no covariance of a track).
  if (!std::isfinite(P.sum())) return -1.0;
  if (cholesky_lower<N>(P, L)) return 0.0;
  P = (0.5 * (P + P.transpose())).eval();
  const double scale = P.diagonal().cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return -1.0;
  for (double rel = 1e-12; rel <= 1.001e-4; rel *= 100.0) {
    Eigen::Matrix<double, N, N> Pj = P;
    Pj.diagonal().array() += rel * scale;
    if (cholesky_lower<N>(Pj, L)) {
      P = Pj;
      return rel * scale;
    }
  }
  return -1.0;
}

// Moments of z = h(x), x ~ N(mean, L L'), by the scaled unscented transform, in the form the
// Joseph update takes:
//   mean  = sum W_m Z_i (the azimuth, element 1, averaged in a chart without the ±pi cut)
//   H     = P_zx P^-1, the statistical linearisation (P_zx = sum W_c dZ_i dX_i')
//   extra = sum W_c (dZ_i - H dX_i)(dZ_i - H dX_i)': the spread the linear part does not explain
// so that P_zz = H P H' + extra and P_xz = P H'. With dX_{±j} = ±c L_j:
//   H L = G',  G_j = (dZ_{+j} - dZ_{-j})' / (2c)     (central differences along the sigma directions)
//   extra = W0c dZ_0 dZ_0' + 2 Wi sum_j s_j s_j',  s_j = (dZ_{+j} + dZ_{-j}) / 2
// "extra" is a sum of outer products: positive semi-definite whenever W0c >= 0, with no
// cancellation (unlike P_zz - H P H'). A filter need not form H: P H' = L L' H' = L G and
// H P H' = G' G.
template <int N, int M>
struct MeasurementMoments {
  Eigen::Matrix<double, M, 1> mean;
  Eigen::Matrix<double, M, N> H;  // formed only when asked (with_H)
  Eigen::Matrix<double, N, M> G;
  Eigen::Matrix<double, M, M> extra;
};

// The state components h reads. A sigma direction L_j that moves none of them gives h(x ± c L_j)
// = h(x) bit for bit (the same arguments), so it is not evaluated: with the Cholesky factor of a
// [p v a] per-axis state, the last column moves only the last acceleration.
template <int N>
using StateMask = std::array<bool, N>;

// The moments above from the measured sigma points: z0 = h(x), *zp[j] = h(x + c L_j),
// *zm[j] = h(x - c L_j), their azimuths (element 1) already within pi of z0's (z0(1) + the wrapped
// difference). Pointers: the points stay where they were evaluated (a direction that moves
// nothing h reads points at z0).
template <int N, int M>
void moments_from_points(const Eigen::Matrix<double, M, 1>& z0, const Eigen::Matrix<double, M, 1>* const (&zp)[N],
                         const Eigen::Matrix<double, M, 1>* const (&zm)[N], const Eigen::Matrix<double, N, N>& L,
                         const ScaledWeights& w, MeasurementMoments<N, M>& out, bool with_H) {
  using VecM = Eigen::Matrix<double, M, 1>;
  const double c = w.spread;
  // Azimuths are taken relative to the centre point's and wrapped: every sigma point lies
  // within pi of it, so the weighted average is an ordinary one in a chart where the ±pi cut
  // does not occur (the plain weighted mean wherever the points spread over less than pi). The
  // circular mean atan2(sum W sin, sum W cos) is the direction of the weighted resultant instead:
  // it differs from the mean once the points lie unevenly, and with a negative W0 it is not an
  // average at all.
  VecM sum = VecM::Zero();
  for (int j = 0; j < N; ++j) sum += *zp[j] + *zm[j];
  VecM mean = w.mean0 * z0 + w.other * sum;
  // Residuals of each point from the mean, azimuth wrapped to (-pi, pi].
  auto residual = [&mean](const VecM& z) {
    VecM d = z - mean;
    d(1) = wrap_angle(d(1));
    return d;
  };
  const VecM d0 = residual(z0);
  Eigen::Matrix<double, N, M>& G = out.G;
  const double half_inv_c = 0.5 / c, spread_weight = 2.0 * w.other;
  double extra[M][M] = {};  // upper triangle, accumulated point by point
  for (int j = 0; j < N; ++j) {
    const VecM dp = residual(*zp[j]), dm = residual(*zm[j]);
    double sj[M];
    for (int a = 0; a < M; ++a) {
      G(j, a) = (dp(a) - dm(a)) * half_inv_c;
      sj[a] = 0.5 * (dp(a) + dm(a));
    }
    for (int a = 0; a < M; ++a) {
      const double wa = spread_weight * sj[a];
      for (int b = a; b < M; ++b) extra[a][b] += wa * sj[b];
    }
  }
  for (int a = 0; a < M; ++a)
    for (int b = a; b < M; ++b) out.extra(a, b) = out.extra(b, a) = extra[a][b] + w.cov0 * d0(a) * d0(b);
  // H = G' L^-1, i.e. L' H' = G.
  if (with_H) out.H.transpose() = L.transpose().template triangularView<Eigen::Upper>().solve(G);
  mean(1) = wrap_angle(mean(1));
  out.mean = mean;
}

// h(const Eigen::Matrix<double, N, 1>&) -> Eigen::Matrix<double, M, 1> with the azimuth in
// element 1 (the SDK's spherical layout [r, az, el(, rdot)]).
template <int N, int M, class MeasurementFn>
void unscented_measurement(const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& L,
                           const ScaledWeights& w, MeasurementFn&& h, MeasurementMoments<N, M>& out,
                           const StateMask<N>* reads = nullptr, bool with_H = true) {
  using VecM = Eigen::Matrix<double, M, 1>;
  using VecN = Eigen::Matrix<double, N, 1>;
  const double c = w.spread;
  const VecM z0 = h(x);
  VecM zp[N], zm[N];
  for (int j = 0; j < N; ++j) {
    bool moves = !reads;
    for (int i = 0; i < N && !moves; ++i) moves = (*reads)[i] && L(i, j) != 0.0;
    if (!moves) {
      zp[j] = zm[j] = z0;  // h(x ± c L_j) = h(x): z0(1) + wrap(0) = z0(1)
    } else {
      const VecN step = c * L.col(j);
      zp[j] = h(VecN(x + step));
      zm[j] = h(VecN(x - step));
      zp[j](1) = z0(1) + wrap_angle(zp[j](1) - z0(1));
      zm[j](1) = z0(1) + wrap_angle(zm[j](1) - z0(1));
    }
  }
  const VecM* pp[N];
  const VecM* pm[N];
  for (int j = 0; j < N; ++j) {
    pp[j] = &zp[j];
    pm[j] = &zm[j];
  }
  moments_from_points<N, M>(z0, pp, pm, L, w, out, with_H);
}

}  // namespace trackflow::ukf
