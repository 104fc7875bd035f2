// Purpose: tests of consistency_test.hpp: effective sample size of white and AR(1) series, the binomial acceptance against a direct sum, and the time average's degrees of freedom.
#include "scoring/consistency_test.hpp"

#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace trackflow;
using namespace trackflow::metrics;

namespace {

std::vector<double> ar1(double phi, std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<double> x(n);
  double v = rng.normal() / std::sqrt(1.0 - phi * phi);  // stationary from the start
  for (auto& e : x) {
    e = v;
    v = phi * v + rng.normal();
  }
  return x;
}

}  // namespace

TEST_CASE("effective sample size of white and AR(1) series") {
  // White noise: about every value counts (the estimator's own spread is a few per cent).
  for (std::uint64_t seed : {1, 2, 3}) CHECK(effective_sample_size(ar1(0.0, 20000, seed)) == Approx(20000).epsilon(0.15));
  // AR(1): tau = (1 + phi) / (1 - phi); for phi = 0.9, 19, i.e. 20000 / 19 = 1053 effective values.
  for (std::uint64_t seed : {4, 5, 6}) CHECK(effective_sample_size(ar1(0.9, 20000, seed)) == Approx(20000.0 / 19.0).epsilon(0.25));
  // A constant series and a short one: every value (nothing to estimate a correlation from).
  CHECK(effective_sample_size(std::vector<double>(50, 1.0)) == 50);
  CHECK(effective_sample_size({1.0, 2.0, 3.0}) == 3);
}

TEST_CASE("binomial acceptance is the binomial lower quantile") {
  for (int n : {1, 5, 7, 20, 90, 600}) {
    for (double confidence : {0.9, 0.95, 0.99}) {
      // Direct: the smallest k with P(X <= k) >= 1 - confidence, the probabilities summed by hand.
      const double p = confidence;
      double cdf = 0.0;
      int k = 0;
      for (; k <= n; ++k) {
        cdf += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) + k * std::log(p) +
                        (n - k) * std::log1p(-p));
        if (cdf >= 1.0 - confidence - 1e-12) break;
      }
      INFO("n " << n << " confidence " << confidence);
      CHECK(binomial_acceptance(n, p, confidence) == Approx(static_cast<double>(k) / n).margin(1e-12));
    }
  }
  // A consistent filter's steps (each inside with probability 0.95) pass at about 95 % of trials.
  Rng rng(9);
  int passed = 0;
  const double accept = binomial_acceptance(200, 0.95, 0.95);
  for (int trial = 0; trial < 4000; ++trial) {
    int inside = 0;
    for (int k = 0; k < 200; ++k) inside += rng.uniform() < 0.95 ? 1 : 0;
    passed += inside >= accept * 200 ? 1 : 0;
  }
  CHECK(passed / 4000.0 >= 0.95);
  CHECK(passed / 4000.0 <= 0.985);  // a discrete quantile: at least the confidence, not far above
}

TEST_CASE("time-average dof counts runs steps and correlation") {
  // K steps of n M dof each: K n M; correlated, divided by tau = K / effective.
  CHECK(time_average_dof(std::vector<double>(600, 1200.0), 600) == Approx(600 * 1200.0));
  CHECK(time_average_dof(std::vector<double>(600, 1200.0), 60) == Approx(60 * 1200.0));
  // Unequal: K^2 / sum(1/dof), the chi-square with the average's variance.
  CHECK(time_average_dof({3.0, 6.0}, 2) == Approx(4.0 / (1.0 / 3 + 1.0 / 6)));
  CHECK(band_has_power(chi_square_band(600, 0.95)));
  CHECK_FALSE(band_has_power(chi_square_band(3, 0.95)));
}
