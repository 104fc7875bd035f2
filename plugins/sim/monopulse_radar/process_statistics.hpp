// Purpose: per-run sums of the radar's own random processes (glint, RCS factor, misses) and the ensemble estimates a pipeline checks against their closed forms.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace trackflow::sim {

// Pooled over all looks of all runs, in run order. Lag-1 products pair each look with the previous
// look of the same run.
struct ProcessStatistics {
  std::uint64_t looks = 0, missed = 0;
  double time_steps = 0.0;  // sum of the intervals between consecutive looks (pairs of them)
  std::uint64_t pairs = 0;
  // Linear glint g (m): zero mean by construction, so moments about zero.
  std::uint64_t glint_n = 0, renewals = 0, laplacian_renewals = 0;
  double g2 = 0.0, g4 = 0.0, g_lag = 0.0, g_prev2 = 0.0;
  // RCS factor x (mean 1).
  double x = 0.0, x2 = 0.0, x_lag = 0.0, x_prev = 0.0, x_cur_paired = 0.0;

  void add(const ProcessStatistics& o) {
    looks += o.looks;
    missed += o.missed;
    time_steps += o.time_steps;
    pairs += o.pairs;
    glint_n += o.glint_n;
    renewals += o.renewals;
    laplacian_renewals += o.laplacian_renewals;
    g2 += o.g2;
    g4 += o.g4;
    g_lag += o.g_lag;
    g_prev2 += o.g_prev2;
    x += o.x;
    x2 += o.x2;
    x_lag += o.x_lag;
    x_prev += o.x_prev;
    x_cur_paired += o.x_cur_paired;
  }

  static double nan() { return std::numeric_limits<double>::quiet_NaN(); }
  double mean_step() const { return pairs ? time_steps / static_cast<double>(pairs) : nan(); }
  double glint_variance() const { return glint_n ? g2 / static_cast<double>(glint_n) : nan(); }
  // E[g^4] / E[g^2]^2 of the zero-mean glint: 3 for a Gaussian, 6 for a Laplacian; the glint
  // mixture's heavy tails (paper 003 eq 3-13) make it large, which is what the AEKF is about.
  double glint_kurtosis() const { return glint_n && g2 > 0.0 ? g4 * static_cast<double>(glint_n) / (g2 * g2) : nan(); }
  // sum g_k g_{k-1} / sum g_{k-1}^2: the lag-1 autocorrelation of a zero-mean process.
  double glint_lag1() const { return g_prev2 > 0.0 ? g_lag / g_prev2 : nan(); }
  double rcs_mean() const { return looks ? x / static_cast<double>(looks) : nan(); }
  double rcs_variance() const {
    if (looks < 2) return nan();
    const double m = rcs_mean();
    return x2 / static_cast<double>(looks) - m * m;
  }
  // Lag-1 autocorrelation of x about the ensemble mean.
  double rcs_lag1() const {
    if (pairs == 0) return nan();
    const double m = rcs_mean();
    const double n = static_cast<double>(pairs);
    const double cov = x_lag / n - m * (x_prev + x_cur_paired) / n + m * m;
    return cov / rcs_variance();
  }
  // Correlation time -dt / ln(rho1) of an exponential autocorrelation.
  static double correlation_time(double rho1, double dt) {
    return rho1 > 0.0 && rho1 < 1.0 ? -dt / std::log(rho1) : nan();
  }
};

}  // namespace trackflow::sim
