// Purpose: the IMM's arithmetic on the common Cartesian state: mode states in and out of it, moment-matched mixing with unequal state sizes, the transition-matrix check, and the log-domain mode-probability update.
#pragma once

#include <trackflow/motion.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace trackflow::imm {

inline constexpr int kMaxModes = 4;
// The common state is the constant-acceleration layout [x vx ax y vy ay z vz az] (motion.hpp).
inline constexpr int kC = 9;
using VecC = Eigen::Matrix<double, kC, 1>;
using MatC = Eigen::Matrix<double, kC, kC>;

// Where component i of an Order-state lives in the common state.
template <int Order>
constexpr int common_index(int i) {
  return (i / Order) * 3 + i % Order;
}
constexpr bool is_acceleration(int c) { return c % 3 == 2; }

// A mode's estimate on the common state; without acceleration (CV) its acceleration entries are
// left as they are and has_acceleration is false.
struct CommonEstimate {
  VecC x = VecC::Zero();
  MatC P = MatC::Zero();
  bool has_acceleration = false;
};

template <int Order>
void to_common(const Eigen::Matrix<double, 3 * Order, 1>& x, const Eigen::Matrix<double, 3 * Order, 3 * Order>& P,
               CommonEstimate& out) {
  constexpr int N = 3 * Order;
  if constexpr (Order == 3) {
    out.x = x;
    out.P = P;
  } else {
    for (int i = 0; i < N; ++i) {
      out.x(common_index<Order>(i)) = x(i);
      for (int j = 0; j < N; ++j) out.P(common_index<Order>(i), common_index<Order>(j)) = P(i, j);
    }
  }
  out.has_acceleration = Order == 3;
}

template <int Order>
void from_common(const VecC& xc, const MatC& Pc, Eigen::Matrix<double, 3 * Order, 1>& x,
                 Eigen::Matrix<double, 3 * Order, 3 * Order>& P) {
  constexpr int N = 3 * Order;
  if constexpr (Order == 3) {
    x = xc;
    P = Pc;
  } else {
    for (int i = 0; i < N; ++i) {
      x(i) = xc(common_index<Order>(i));
      for (int j = 0; j < N; ++j) P(i, j) = Pc(common_index<Order>(i), common_index<Order>(j));
    }
  }
}

// Moment-matched mixture sum_i w_i N(x_i, P_i) on the common state (weights sum to 1; zero
// weights are skipped). A mode without acceleration has none to contribute: its acceleration is
// taken as the reference's (ref_x, ref_P acceleration entries), uncorrelated with its position
// and velocity — the "unbiased mixing" of Granström, Willett & Bar-Shalom (2015): augmenting with
// zero would pull the receiving mode's acceleration towards zero by the CV weight at every step,
// a bias no model asked for. Position and velocity are mixed exactly whatever the reference.
// Only the upper triangle is summed, then mirrored. acceleration: whether to form the
// acceleration entries at all (a CV receiver needs only position and velocity).
inline void mix(const CommonEstimate* modes, const double* w, int count, const VecC& ref_x, const MatC& ref_P,
                bool acceleration, VecC& x, MatC& P) {
  VecC xi[kMaxModes];
  for (int i = 0; i < count; ++i) {
    xi[i] = modes[i].x;
    if (!modes[i].has_acceleration)
      for (int a = 0; a < 3; ++a) xi[i](3 * a + 2) = ref_x(3 * a + 2);
  }
  x.setZero();
  for (int i = 0; i < count; ++i)
    if (w[i] > 0.0) x += w[i] * xi[i];
  P.setZero();
  for (int i = 0; i < count; ++i) {
    if (!(w[i] > 0.0)) continue;
    const VecC d = xi[i] - x;
    const bool own = modes[i].has_acceleration;
    for (int c = 0; c < kC; ++c) {
      if (!acceleration && is_acceleration(c)) continue;
      for (int r = 0; r <= c; ++r) {
        if (!acceleration && is_acceleration(r)) continue;
        double p;
        if (own || (!is_acceleration(r) && !is_acceleration(c)))
          p = modes[i].P(r, c);
        else if (is_acceleration(r) && is_acceleration(c))
          p = ref_P(r, c);
        else
          p = 0.0;  // the borrowed acceleration is uncorrelated with the mode's own states
        P(r, c) += w[i] * (p + d(r) * d(c));
      }
    }
  }
  for (int c = 0; c < kC; ++c)
    for (int r = 0; r < c; ++r) P(c, r) = P(r, c);
}

// Transition matrix (row-major, rows "from", columns "to"): count x count, entries in [0, 1],
// each row summing to 1 within 1e-9. Returns why not, or empty.
inline std::string check_transition(const std::vector<double>& pi, int count) {
  if (static_cast<int>(pi.size()) != count * count)
    return "the transition matrix has " + std::to_string(pi.size()) + " entries; " + std::to_string(count) +
           " modes need " + std::to_string(count * count) + " (row-major: row i = from mode i)";
  for (int i = 0; i < count; ++i) {
    double sum = 0.0;
    for (int j = 0; j < count; ++j) {
      const double p = pi[static_cast<size_t>(i * count + j)];
      if (!(p >= 0.0 && p <= 1.0))
        return "transition matrix entry (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) + ") = " +
               std::to_string(p) + " is not a probability";
      sum += p;
    }
    if (std::fabs(sum - 1.0) > 1e-9)
      return "row " + std::to_string(i + 1) + " of the transition matrix sums to " + std::to_string(sum) +
             "; each row (the probabilities of leaving mode " + std::to_string(i + 1) + ") must sum to 1";
  }
  return {};
}

// Predicted mode probabilities c_j = sum_i pi_ij mu_i and mixing weights w[j][i] = pi_ij mu_i / c_j
// (Blom & Bar-Shalom 1988, step 1).
inline void mixing_weights(const double* pi, const double* mu, int count, double* c, double w[][kMaxModes]) {
  for (int j = 0; j < count; ++j) {
    c[j] = 0.0;
    for (int i = 0; i < count; ++i) c[j] += pi[i * count + j] * mu[i];
    for (int i = 0; i < count; ++i) w[j][i] = c[j] > 0.0 ? pi[i * count + j] * mu[i] / c[j] : (i == j ? 1.0 : 0.0);
  }
}

// Gaussian log-likelihood of an innovation: -1/2 (nis + log det S + M log 2 pi), log det S from
// its Cholesky factor. -inf when S is not positive definite.
template <int M>
double log_likelihood(const Eigen::Matrix<double, M, M>& S, double nis) {
  double logdet = 0.0;
  Eigen::Matrix<double, M, M> L = S;  // lower triangle overwritten by the factor
  for (int j = 0; j < M; ++j) {
    double d = L(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > 0.0)) return -std::numeric_limits<double>::infinity();
    L(j, j) = std::sqrt(d);
    logdet += 2.0 * std::log(L(j, j));
    for (int i = j + 1; i < M; ++i) {
      double s = L(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / L(j, j);
    }
  }
  constexpr double kLog2Pi = 1.8378770664093454836;
  return -0.5 * (nis + logdet + M * kLog2Pi);
}

// mu_j = c_j exp(l_j) / sum_k c_k exp(l_k), in the log domain (the largest log c_j + l_j is
// subtracted before exponentiating: likelihoods of a 4-D innovation can underflow to 0 for every
// mode after a large manoeuvre, which would divide 0 by 0). Returns false (mu = c) when no mode
// has a finite likelihood.
inline bool update_probabilities(const double* c, const double* loglik, int count, double* mu) {
  double top = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < count; ++j)
    if (c[j] > 0.0 && std::isfinite(loglik[j])) top = std::max(top, std::log(c[j]) + loglik[j]);
  if (!std::isfinite(top)) {
    std::copy(c, c + count, mu);
    return false;
  }
  double sum = 0.0;
  for (int j = 0; j < count; ++j) {
    mu[j] = c[j] > 0.0 && std::isfinite(loglik[j]) ? std::exp(std::log(c[j]) + loglik[j] - top) : 0.0;
    sum += mu[j];
  }
  for (int j = 0; j < count; ++j) mu[j] /= sum;  // sum >= 1: the top term is exp(0)
  return true;
}

}  // namespace trackflow::imm
