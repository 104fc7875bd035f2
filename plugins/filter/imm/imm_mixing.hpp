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
// zero and has_acceleration is false.
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
    out.x.setZero();
    out.P.setZero();
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

// The modes as mix() reads them: states on the common layout, by pointer (a 9-state mode's own
// x and P need no copy); a mode without acceleration has zero acceleration entries in x and P.
struct ModeView {
  const VecC* x[kMaxModes] = {};
  const MatC* P[kMaxModes] = {};
  bool has_acceleration[kMaxModes] = {};
  int count = 0;
};

// Moment-matched mixture sum_i w_i N(x_i, P_i) on the common state (weights sum to 1; zero
// weights are skipped). A mode without acceleration has none to contribute: its acceleration is
// taken as the reference's (ref_x, ref_P acceleration entries), uncorrelated with its position
// and velocity — the "unbiased mixing" of Granström, Willett & Bar-Shalom (2015): augmenting with
// zero would pull the receiving mode's acceleration towards zero by the CV weight at every step,
// a bias no model asked for. Position and velocity are mixed exactly whatever the reference.
// The upper triangle is summed column by column (contiguous, no branch: it vectorises), then
// mirrored.
inline void mix(const ModeView& modes, const double* w, const VecC& ref_x, const MatC& ref_P, VecC& x, MatC& P) {
  VecC borrowed[kMaxModes];
  const VecC* xi[kMaxModes];
  for (int i = 0; i < modes.count; ++i) {
    xi[i] = modes.x[i];
    if (!modes.has_acceleration[i]) {
      borrowed[i] = *modes.x[i];
      for (int a = 0; a < 3; ++a) borrowed[i](3 * a + 2) = ref_x(3 * a + 2);
      xi[i] = &borrowed[i];
    }
  }
  x.setZero();
  for (int i = 0; i < modes.count; ++i)
    if (w[i] > 0.0) x += w[i] * *xi[i];
  P.setZero();
  for (int i = 0; i < modes.count; ++i) {
    if (!(w[i] > 0.0)) continue;
    const double wi = w[i];
    const VecC d = *xi[i] - x;
    const MatC& Pi = *modes.P[i];
    for (int c = 0; c < kC; ++c) {
      const double wd = wi * d(c);
      for (int r = 0; r <= c; ++r) P(r, c) += wi * Pi(r, c) + wd * d(r);
    }
    if (!modes.has_acceleration[i])  // the borrowed acceleration's covariance (its own entries are zero)
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a <= b; ++a) P(3 * a + 2, 3 * b + 2) += wi * ref_P(3 * a + 2, 3 * b + 2);
  }
  for (int c = 0; c < kC; ++c)
    for (int r = 0; r < c; ++r) P(c, r) = P(r, c);
}

// The same from CommonEstimate copies.
inline void mix(const CommonEstimate* modes, const double* w, int count, const VecC& ref_x, const MatC& ref_P, VecC& x,
                MatC& P) {
  ModeView v;
  v.count = count;
  for (int i = 0; i < count; ++i) {
    v.x[i] = &modes[i].x;
    v.P[i] = &modes[i].P;
    v.has_acceleration[i] = modes[i].has_acceleration;
  }
  mix(v, w, ref_x, ref_P, x, P);
}

// The combined estimate of the modes with probabilities mu, moment-matched on the common state.
// The acceleration of a mode without one is the probability-weighted acceleration of the modes
// that carry it (every mode mixed into that reference has its own acceleration, so the reference
// passed to that mixture is never read).
inline void combine(const ModeView& v, const double* mu, VecC& x0, MatC& P0) {
  bool any_acceleration = false, all_acceleration = true;
  for (int i = 0; i < v.count; ++i) {
    any_acceleration = any_acceleration || v.has_acceleration[i];
    all_acceleration = all_acceleration && v.has_acceleration[i];
  }
  VecC ref_x = VecC::Zero();
  MatC ref_P = MatC::Zero();
  if (any_acceleration && !all_acceleration) {
    double wa[kMaxModes] = {}, total = 0.0;
    for (int i = 0; i < v.count; ++i)
      if (v.has_acceleration[i]) total += mu[i];
    for (int i = 0; i < v.count; ++i)
      if (v.has_acceleration[i]) wa[i] = total > 0.0 ? mu[i] / total : 1.0;
    double sum = 0.0;
    for (int i = 0; i < v.count; ++i) sum += wa[i];
    for (int i = 0; i < v.count; ++i) wa[i] /= sum;
    mix(v, wa, ref_x, ref_P, x0, P0);
    ref_x = x0;
    ref_P = P0;
  }
  mix(v, mu, ref_x, ref_P, x0, P0);
}

// The combined estimate (combine) into e: the 9 common states when any mode has acceleration,
// otherwise the constant-velocity 6 [x vx y vy z vz]; and the ENU position/velocity block.
template <class Estimate>
void publish(const VecC& x0, const MatC& P0, bool any_acceleration, Estimate& e) {
  const int n = any_acceleration ? 9 : 6;
  e.state.resize(n);
  e.covariance.resize(n, n);
  int idx[6];
  if (any_acceleration) {
    e.state.template head<9>() = x0;
    e.covariance.template topLeftCorner<9, 9>() = P0;
    for (int a = 0; a < 3; ++a) {
      idx[a] = 3 * a;
      idx[a + 3] = 3 * a + 1;
    }
  } else {
    for (int i = 0; i < 6; ++i) {
      e.state(i) = x0(common_index<2>(i));
      for (int k = 0; k < 6; ++k) e.covariance(i, k) = P0(common_index<2>(i), common_index<2>(k));
    }
    for (int a = 0; a < 3; ++a) {
      idx[a] = 2 * a;
      idx[a + 3] = 2 * a + 1;
    }
  }
  for (int i = 0; i < 6; ++i) {
    e.enu(i) = e.state(idx[i]);
    for (int k = 0; k < 6; ++k) e.enu_covariance(i, k) = e.covariance(idx[i], idx[k]);
  }
}

// The measurement-prediction mixture: z^ = sum c_j z^_j, so nu = sum c_j nu_j and
// S = sum c_j (S_j + (nu_j - nu)(nu_j - nu)'), over the modes that updated (weights renormalised).
template <int M>
void innovation_mixture(const double* c, const bool* used, int count, const Eigen::Matrix<double, M, 1>* const* nu_j,
                        const Eigen::Matrix<double, M, M>* const* S_j, Eigen::Matrix<double, M, 1>& nu,
                        Eigen::Matrix<double, M, M>& S) {
  using VecM = Eigen::Matrix<double, M, 1>;
  double total = 0.0;
  for (int j = 0; j < count; ++j)
    if (used[j]) total += c[j];
  nu.setZero();
  S.setZero();
  for (int j = 0; j < count; ++j)
    if (used[j] && total > 0.0) nu += (c[j] / total) * *nu_j[j];
  for (int j = 0; j < count; ++j)
    if (used[j] && total > 0.0) {
      const VecM d = *nu_j[j] - nu;
      S += (c[j] / total) * (*S_j[j] + d * d.transpose());
    }
}

// A mode that could not update (used false, or a likelihood that is not finite) is neither
// favoured nor dropped: it gets the worst likelihood of the modes that did. false (ll unchanged)
// when no mode did.
inline bool floor_likelihoods(double* ll, const bool* used, int count) {
  bool any = false;
  double worst = std::numeric_limits<double>::infinity();
  for (int j = 0; j < count; ++j)
    if (used[j] && std::isfinite(ll[j])) {
      any = true;
      worst = std::min(worst, ll[j]);
    }
  if (!any) return false;
  for (int j = 0; j < count; ++j)
    if (!used[j] || !std::isfinite(ll[j])) ll[j] = worst;
  return true;
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

// Gaussian log-likelihood of an innovation with NIS nu' S^-1 nu and det S (both from the update's
// Cholesky factor of S): -1/2 (nis + ln det S + M ln 2 pi). -inf unless det S > 0.
inline double log_likelihood(int M, double nis, double det_S) {
  if (!(det_S > 0.0)) return -std::numeric_limits<double>::infinity();
  constexpr double kLog2Pi = 1.8378770664093454836;
  return -0.5 * (nis + std::log(det_S) + M * kLog2Pi);
}
// The same from ln det S (PredictedMeasurement::log_det_S, set_log_det). -inf unless it is finite.
inline double log_likelihood_from_log_det(int M, double nis, double log_det_S) {
  if (!std::isfinite(log_det_S) || !std::isfinite(nis)) return -std::numeric_limits<double>::infinity();
  constexpr double kLog2Pi = 1.8378770664093454836;
  return -0.5 * (nis + log_det_S + M * kLog2Pi);
}

// nu' S^-1 nu for a symmetric positive definite M x M S (Cholesky, unrolled for M <= 4); false
// when S is not positive definite.
template <int M>
bool quadratic_form(const Eigen::Matrix<double, M, M>& S, const Eigen::Matrix<double, M, 1>& nu, double& nis) {
  double L[M][M] = {}, y[M];
  nis = 0.0;
  for (int j = 0; j < M; ++j) {
    double d = S(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;
    L[j][j] = std::sqrt(d);
    const double inv = 1.0 / L[j][j];
    for (int i = j + 1; i < M; ++i) {
      double s = S(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s * inv;
    }
    double s = nu(j);  // forward substitution L y = nu, row j
    for (int k = 0; k < j; ++k) s -= L[j][k] * y[k];
    y[j] = s * inv;
    nis += y[j] * y[j];
  }
  return true;
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
