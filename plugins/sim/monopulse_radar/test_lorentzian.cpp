// Purpose: tests of the Lorentzian-spectrum samplers: the Gaussian AR(1) and the DAR(1) renewal process (eq 3-10, 3-15).
#include "lorentzian_process.hpp"
#include "test_statistics.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace trackflow;
using namespace trackflow::sim;
namespace ts = trackflow::test_stats;

// exp(-2 pi B tau) is the autocorrelation whose spectrum is 2B / (pi (B^2 + f^2)) (eq 3-10): correlation
// time 1/(2 pi B) = 0.159 s at B = 1 Hz.
TEST_CASE("lorentzian correlation is exp of minus 2 pi B dt") {
  CHECK(lorentzian_correlation(1.0, 1.0 / (2 * std::numbers::pi)) == Approx(std::exp(-1.0)).epsilon(1e-15));
  CHECK(lorentzian_correlation(2.0, 0.05) == Approx(lorentzian_correlation(1.0, 0.1)).epsilon(1e-15));
  CHECK(lorentzian_correlation(5.0, 0.0) == 1.0);
}

// 200 000 samples at 20 Hz, B = 1 Hz (rho = 0.7304): unit variance and autocorrelation rho^k at lags 1, 3,
// 10. Bounds: 5 batch-means standard errors (50 batches of 4000 samples, 640 correlation times each)
// plus the estimator's O(1/n) bias, 3/n.
TEST_CASE("gauss markov variance 1 and rho^k lags") {
  Rng rng(7);
  const double dt = 0.05, B = 1.0, rho = lorentzian_correlation(B, dt);
  GaussMarkov g;
  g.start(rng);
  std::vector<double> x;
  for (int i = 0; i < 200000; ++i) {
    g.advance(rho, rng);
    x.push_back(g.value());
  }
  const auto var = ts::batch_means(x, 50, ts::variance);
  CHECK(std::abs(var.value - 1.0) < 5 * var.standard_error + 3.0 / 4000);
  for (std::size_t k : {1u, 3u, 10u}) {
    const auto r = ts::batch_means(x, 50, [k](const std::vector<double>& b) { return ts::autocorrelation(b, k); });
    CHECK(std::abs(r.value - std::pow(rho, static_cast<double>(k))) < 5 * r.standard_error + 3.0 / 4000);
  }
  // Correlation time recovered from the lag-1 coefficient: -dt / ln r1 = 1 / (2 pi B).
  const auto r1 = ts::batch_means(x, 50, [](const std::vector<double>& b) { return ts::autocorrelation(b, 1); });
  const double tau = -dt / std::log(r1.value);
  const double tau_se = dt * r1.standard_error / (r1.value * std::log(r1.value) * std::log(r1.value));
  CHECK(std::abs(tau - 1.0 / (2 * std::numbers::pi * B)) < 5 * tau_se + 0.002);
}

// DAR(1) with an exponential marginal (strongly non-Gaussian): the marginal stays exponential (mean 1,
// P(x > 3) = e^-3) and the autocorrelation is rho^k exactly; the value is kept with probability rho.
TEST_CASE("dar1 keeps its marginal with rho^k correlation") {
  Rng rng(11);
  const double rho = lorentzian_correlation(2.0, 0.05);  // 0.5335
  double v = -std::log(rng.uniform());
  std::vector<double> x;
  long kept = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    if (dar1_renew(rho, rng))
      v = -std::log(rng.uniform());
    else
      ++kept;
    x.push_back(v);
  }
  const double p = static_cast<double>(kept) / n;
  CHECK(std::abs(p - rho) < 5 * std::sqrt(rho * (1 - rho) / n));
  const auto m = ts::batch_means(x, 50, ts::mean);
  CHECK(std::abs(m.value - 1.0) < 5 * m.standard_error);
  const auto tail = ts::batch_means(x, 50, [](const std::vector<double>& b) {
    double c = 0;
    for (double y : b) c += y > 3.0;
    return c / static_cast<double>(b.size());
  });
  CHECK(std::abs(tail.value - std::exp(-3.0)) < 5 * tail.standard_error);
  for (std::size_t k : {1u, 2u, 5u}) {
    const auto r = ts::batch_means(x, 50, [k](const std::vector<double>& b) { return ts::autocorrelation(b, k); });
    CHECK(std::abs(r.value - std::pow(rho, static_cast<double>(k))) < 5 * r.standard_error + 3.0 / 4000);
  }
}
