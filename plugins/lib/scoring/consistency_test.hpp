// Purpose: the two consistency tests of a series of per-step normalised squared errors (ANEES_k, ANIS_k): the time average against a band that counts runs, steps and their correlation, and the fraction of steps inside their own band with its binomial acceptance.
#pragma once

#include "chi_square_band.hpp"

#include <boost/math/distributions/binomial.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace trackflow::metrics {

// Effective number of independent values in a stationary series x_0..x_{K-1}: K / tau with the
// integrated autocorrelation time tau = -1 + 2 sum_m (g_{2m} + g_{2m+1}) / g_0, summed while the
// pair sums stay positive (Geyer 1992, "Practical Markov chain Monte Carlo", Stat. Sci. 7(4),
// initial positive sequence estimator, §3.3). A white series gives about K; an AR(1) series with
// coefficient phi gives about K (1 - phi) / (1 + phi). Lags are summed up to max_lag (bounded
// cost on long series; the estimate is then a lower bound of tau). Clamped to [1, K].
inline double effective_sample_size(const std::vector<double>& x, std::size_t max_lag = 2000) {
  const std::size_t K = x.size();
  if (K < 4) return static_cast<double>(K);
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(K);
  auto autocovariance = [&](std::size_t lag) {
    double s = 0.0;
    for (std::size_t k = 0; k + lag < K; ++k) s += (x[k] - mean) * (x[k + lag] - mean);
    return s / static_cast<double>(K);  // the biased estimator: a positive semi-definite sequence
  };
  const double g0 = autocovariance(0);
  if (!(g0 > 0.0)) return static_cast<double>(K);  // a constant series: nothing to correlate
  double pairs = 0.0;
  const std::size_t lags = std::min(max_lag, K / 2);
  for (std::size_t m = 0; 2 * m + 1 < lags; ++m) {
    const double pair = (m == 0 ? g0 : autocovariance(2 * m)) + autocovariance(2 * m + 1);
    if (!(pair > 0.0)) break;
    pairs += pair;
  }
  const double tau = std::max(1e-300, -1.0 + 2.0 * pairs / g0);
  return std::clamp(static_cast<double>(K) / tau, 1.0, static_cast<double>(K));
}

// The lowest fraction of n independent steps inside their band (each inside with probability p
// when the filter is consistent) still accepted at `confidence`: the (1 - confidence) quantile of
// Binomial(n, p), over n. n is rounded to the nearest whole number of steps, at least 1.
inline double binomial_acceptance(double n, double p, double confidence) {
  const double trials = std::max(1.0, std::round(n));
  const boost::math::binomial_distribution<double> b(trials, p);
  // The smallest count whose lower tail P(X <= count) reaches 1 - confidence (a count below it
  // would happen with probability below 1 - confidence).
  // Bisection on the monotone CDF: O(log n) evaluations.
  double lo = 0.0, hi = trials;  // cdf(hi) = 1 >= 1 - confidence
  if (boost::math::cdf(b, lo) >= 1.0 - confidence) return 0.0;
  while (hi - lo > 1.0) {  // invariant: cdf(lo) < 1 - confidence <= cdf(hi)
    const double mid = std::floor(0.5 * (lo + hi));
    (boost::math::cdf(b, mid) < 1.0 - confidence ? lo : hi) = mid;
  }
  return hi / trials;
}

// The time average of K per-step values, each with `dof_k` degrees of freedom (n M_k for ANEES,
// the innovation dimensions summed over runs for ANIS): without correlation its variance is
// (2 / K^2) sum 1 / dof_k, a chi-square's of nu = K^2 / sum(1 / dof_k) degrees of freedom (= K n M
// when every step has all M runs); correlated steps divide nu by tau = K / effective steps.
inline double time_average_dof(const std::vector<double>& dof, double effective_steps) {
  double inverse = 0.0;
  for (double d : dof) inverse += 1.0 / d;
  const double K = static_cast<double>(dof.size());
  if (!(inverse > 0.0)) return 0.0;
  return K * K / inverse * (effective_steps / K);
}

// A test has power when it could tell a covariance wrong by a factor of two: the average's band
// lies inside (0.5, 2); the per-step test counts at least 5 independent steps (its acceptance is
// then 0.75-0.85 of the steps at 95 %; with fewer it cannot reject anything clearly, and the
// acceptance of a discrete count jumps with each step).
inline bool band_has_power(const Band& b) { return b.lo > 0.5 && b.hi < 2.0; }
inline constexpr double kMinEffectiveSteps = 5.0;

}  // namespace trackflow::metrics
