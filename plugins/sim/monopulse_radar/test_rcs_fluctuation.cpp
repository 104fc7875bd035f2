// Purpose: tests of the Swerling RCS fluctuation: exponential and chi-square-4 marginals, eq 3-15 correlation, scan hold, the shared uniform.
#include "rcs_fluctuation.hpp"
#include "test_statistics.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace trackflow;
using namespace trackflow::sim;
namespace ts = trackflow::test_stats;

namespace {

// n looks dt apart from one RcsFluctuation.
std::vector<double> series(SwerlingCase c, double B, double dt, int n, std::uint64_t seed, std::vector<double>* u = nullptr) {
  Rng rng(seed);
  RcsFluctuation rcs(c, B, 1.0);
  rcs.start(0.0, rng);
  std::vector<double> x;
  for (int i = 0; i < n; ++i) {
    rcs.advance(i * dt, rng);
    x.push_back(rcs.factor());
    if (u) u->push_back(rcs.uniform());
  }
  return x;
}

double fraction_above(const std::vector<double>& b, double a) {
  double c = 0;
  for (double y : b) c += y > a;
  return c / static_cast<double>(b.size());
}

}  // namespace

// Swerling II: the power of a complex Gaussian, exponential with mean 1: variance 1, P(x > a) = e^-a.
// 200 000 looks 0.1 s apart at B = 1 Hz (correlation 0.28 between looks): 5 batch-means standard errors.
TEST_CASE("swerling2 rcs is exponential with mean 1") {
  const auto x = series(SwerlingCase::Two, 1.0, 0.1, 200000, 3);
  const auto m = ts::batch_means(x, 50, ts::mean);
  CHECK(std::abs(m.value - 1.0) < 5 * m.standard_error);
  const auto v = ts::batch_means(x, 50, ts::variance);
  CHECK(std::abs(v.value - 1.0) < 5 * v.standard_error);
  for (double a : {0.1, 1.0, 3.0}) {
    const auto p = ts::batch_means(x, 50, [a](const std::vector<double>& b) { return fraction_above(b, a); });
    CHECK(std::abs(p.value - std::exp(-a)) < 5 * p.standard_error);
  }
}

// Swerling IV: chi-square with 4 degrees of freedom over 4: mean 1, variance 1/2, P(x > a) = (1 + 2a) e^-2a.
TEST_CASE("swerling4 rcs is chi square 4 with mean 1") {
  const auto x = series(SwerlingCase::Four, 1.0, 0.1, 200000, 5);
  const auto m = ts::batch_means(x, 50, ts::mean);
  CHECK(std::abs(m.value - 1.0) < 5 * m.standard_error);
  const auto v = ts::batch_means(x, 50, ts::variance);
  CHECK(std::abs(v.value - 0.5) < 5 * v.standard_error);
  const auto p = ts::batch_means(x, 50, [](const std::vector<double>& b) { return fraction_above(b, 2.0); });
  CHECK(std::abs(p.value - 5.0 * std::exp(-4.0)) < 5 * p.standard_error);
}

// The I/Q components have eq 3-15's spectrum, correlation rho = exp(-2 pi B tau); the power of a complex
// Gaussian then has correlation rho^2 (for II and IV alike). At 20 Hz and B = 1 Hz: 0.5335 at lag 1.
TEST_CASE("rcs power decorrelates as rho squared") {
  const double rho = lorentzian_correlation(1.0, 0.05);
  for (auto c : {SwerlingCase::Two, SwerlingCase::Four}) {
    const auto x = series(c, 1.0, 0.05, 200000, 9);
    for (std::size_t k : {1u, 4u}) {
      const auto r = ts::batch_means(x, 50, [k](const std::vector<double>& b) { return ts::autocorrelation(b, k); });
      CHECK(std::abs(r.value - std::pow(rho, 2.0 * static_cast<double>(k))) < 5 * r.standard_error + 3.0 / 4000);
    }
  }
}

// Swerling I and III hold the value over each scan (scan_period 1 s) and change between scans.
TEST_CASE("swerling1 holds within a scan") {
  Rng rng(4);
  RcsFluctuation rcs(SwerlingCase::One, 1.0, 1.0);
  rcs.start(0.0, rng);
  const double first = rcs.factor();
  for (double t : {0.2, 0.5, 0.99}) {
    rcs.advance(t, rng);
    CHECK(rcs.factor() == first);
  }
  rcs.advance(1.01, rng);
  CHECK(rcs.factor() != first);
}

// F(x) is uniform whatever the case (probability integral transform): mean 1/2, P(U < 0.1) = 0.1, and
// small in a fade.
TEST_CASE("rcs uniform variate is uniform") {
  for (auto c : {SwerlingCase::Two, SwerlingCase::Three}) {
    std::vector<double> u;
    series(c, 1.0, 0.5, 100000, 21, &u);
    const auto m = ts::batch_means(u, 50, ts::mean);
    CHECK(std::abs(m.value - 0.5) < 5 * m.standard_error);
    const auto p = ts::batch_means(u, 50, [](const std::vector<double>& b) { return 1.0 - fraction_above(b, 0.1); });
    CHECK(std::abs(p.value - 0.1) < 5 * p.standard_error);
  }
  CHECK(rcs_cdf(0.01, 2) == Approx(1 - std::exp(-0.01)).epsilon(1e-12));
  CHECK(rcs_cdf(0.3, 4) == Approx(1 - 1.6 * std::exp(-0.6)).epsilon(1e-12));
  CHECK(std::isnan(RcsFluctuation(SwerlingCase::Constant, 1, 1).uniform()));
}
