// Purpose: tests of the glint mixture (eq 3-9..3-11): its variances, marginal, Lorentzian correlation, per-axis split and the RCS coupling.
#include "glint.hpp"
#include "process_statistics.hpp"
#include "test_statistics.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

using namespace trackflow;
using namespace trackflow::sim;
namespace ts = trackflow::test_stats;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Draws {
  std::vector<double> linear, az, el, fade;
  long laplacian = 0;
};

// n independent renewals (each a fresh start), with the fade uniform drawn independently (coupled) or
// absent (NaN: the glint's own).
Draws renewals(const GlintSettings& s, int n, bool coupled, std::uint64_t seed) {
  Rng rng(seed), fade_rng(seed + 1000);
  GlintProcess g(s);
  Draws d;
  for (int i = 0; i < n; ++i) {
    const double u = fade_rng.uniform();
    g.start(coupled ? u : kNaN, rng);
    d.linear.push_back(g.linear());
    d.az.push_back(g.azimuth_m());
    d.el.push_back(g.elevation_m());
    d.fade.push_back(u);
    d.laplacian += g.laplacian();
  }
  return d;
}

double mean_square(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return s / static_cast<double>(x.size());
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = ts::mean(a), mb = ts::mean(b);
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

}  // namespace

// The paper's numbers: sigma = 0.2 x 47.5 m = 9.5 m, i = 0.5, ratio 100: s_g^2 = 90.25 / 50.5 = 1.787,
// s_l^2 = 178.7 (Fig 15's values).
TEST_CASE("glint mixture variances are 1.787 and 178.7") {
  GlintSettings s;
  const MixtureVariances v = mixture_variances(s);
  CHECK(v.gaussian == Approx(1.787).margin(5e-4));
  CHECK(v.laplacian == Approx(178.7).margin(0.05));
  CHECK(0.5 * v.gaussian + 0.5 * v.laplacian == Approx(9.5 * 9.5).epsilon(1e-14));
}

// 400 000 renewals: variance 0.5 * 1.787 + 0.5 * 178.7 = 90.24 m^2. Standard error of the mean square:
// sqrt((E g^4 - sigma^4) / n), E g^4 = 0.5 * 3 * 1.787^2 + 0.5 * 6 * 178.7^2 = 95 805 (the Laplacian's
// fourth moment is 6 var^2): 0.468 m^2; bound 5 of them (2.3 m^2). Laplacian fraction i = 0.5 within 5
// binomial standard errors; P(|L| > s_l) = exp(-sqrt 2) for the Laplacian draws.
TEST_CASE("glint mixture variance is 90.24 m2") {
  GlintSettings s;
  const int n = 400000;
  for (bool coupled : {false, true}) {
    const Draws d = renewals(s, n, coupled, 17);
    const double fourth = 0.5 * 3 * 1.787 * 1.787 + 0.5 * 6 * 178.7 * 178.7;
    const double se = std::sqrt((fourth - 90.25 * 90.25) / n);
    CHECK(std::abs(mean_square(d.linear) - 90.24) < 5 * se);
    CHECK(std::abs(static_cast<double>(d.laplacian) / n - 0.5) < 5 * std::sqrt(0.25 / n));
    const double sl = std::sqrt(mixture_variances(s).laplacian), sg = std::sqrt(mixture_variances(s).gaussian);
    // Above 8 s_g = 10.7 m only the Laplacian contributes (Gaussian tail 1e-15): 0.5 exp(-sqrt2 * 10.7/s_l).
    double above = 0;
    for (double g : d.linear) above += std::abs(g) > 8 * sg;
    const double p = 0.5 * std::exp(-std::sqrt(2.0) * 8 * sg / sl);
    CHECK(std::abs(above / n - p) < 5 * std::sqrt(p * (1 - p) / n));
    // The shape the summary reports (glint_kurtosis, process_statistics.hpp): E g^4 / sigma^4 =
    // 95 805 / 90.25^2 = 11.76. Its standard error from E g^8 = 0.5 * 105 s_g^8 + 0.5 * 2520 s_l^8
    // (the Laplacian's eighth moment is 8! b^8 = 2520 var^4): ~0.22 at n = 400 000; bound 5 of them.
    ProcessStatistics stats;
    for (double g : d.linear) {
      ++stats.glint_n;
      stats.g2 += g * g;
      stats.g4 += g * g * g * g;
    }
    const double eighth = 0.5 * 105 * std::pow(1.787, 4) + 0.5 * 2520 * std::pow(178.7, 4);
    const double kurtosis_se = std::sqrt((eighth - fourth * fourth) / n) / (90.25 * 90.25);
    CHECK(std::abs(stats.glint_kurtosis() - fourth / (90.25 * 90.25)) < 5 * kurtosis_se);
  }
}

// per_plane: each plane gets sigma^2 (the rotated glint is sqrt 2 larger); rotated: sigma^2 / 2. Fourth
// moment of an axis: E[(c g cos a)^4] = c^4 E g^4 3/8.
TEST_CASE("glint per axis variance follows glint_axes") {
  const int n = 400000;
  for (bool per_plane : {true, false}) {
    GlintSettings s;
    s.per_plane = per_plane;
    const Draws d = renewals(s, n, false, 23);
    const double c2 = per_plane ? 2.0 : 1.0;
    const double expected = c2 * 90.25 / 2;
    const double fourth = c2 * c2 * 95805.0 * 3.0 / 8.0;
    const double se = std::sqrt((fourth - expected * expected) / n);
    CHECK(std::abs(mean_square(d.az) - expected) < 5 * se);
    CHECK(std::abs(mean_square(d.el) - expected) < 5 * se);
    CHECK(std::abs(correlation(d.az, d.el)) < 5 / std::sqrt(static_cast<double>(n)) * 2);
  }
}

// One random source (Fig 9c): with the Laplacian scale E = -ln U taken from the RCS's uniform U, the glint
// is uncorrelated with U but not independent of it: Cov(g^2, U) = i s_l^2 Cov(-ln U, U) = 0.5 * 178.7 *
// (-1/4), a correlation of -22.34 / (sqrt(87 660) sqrt(1/12)) = -0.261. Without coupling it is 0.
// Bounds: 5 batch-means standard errors (heavy tails: no normal-theory bound).
TEST_CASE("glint shares the rcs uniform when coupled") {
  GlintSettings s;
  const int n = 400000;
  for (bool coupled : {true, false}) {
    const Draws d = renewals(s, n, coupled, 29);
    std::vector<double> g2, pair;
    for (double g : d.linear) g2.push_back(g * g);
    const std::size_t b = n / 50;
    std::vector<double> corr_sq, corr_lin;
    for (int k = 0; k < 50; ++k) {
      auto slice = [&](const std::vector<double>& v) { return std::vector<double>(v.begin() + k * b, v.begin() + (k + 1) * b); };
      corr_sq.push_back(correlation(slice(g2), slice(d.fade)));
      corr_lin.push_back(correlation(slice(d.linear), slice(d.fade)));
    }
    const double expected = coupled ? -0.5 * 178.7 * 0.25 / (std::sqrt(87660.0) * std::sqrt(1.0 / 12)) : 0.0;
    CHECK(std::abs(ts::mean(corr_sq) - expected) < 5 * std::sqrt(ts::variance(corr_sq) / 50));
    CHECK(std::abs(ts::mean(corr_lin)) < 5 * std::sqrt(ts::variance(corr_lin) / 50));
  }
}

// The DAR(1) glint, sampled at 20 Hz with B = 1 Hz: autocorrelation rho^k (eq 3-10's Lorentzian) for the
// linear glint and each axis (the angle alpha renews with the glint), and the variance unchanged.
TEST_CASE("glint autocorrelation is lorentzian") {
  GlintSettings s;
  Rng rng(31);
  GlintProcess g(s);
  g.start(kNaN, rng);
  const double dt = 0.05, rho = lorentzian_correlation(s.bandwidth, dt);
  std::vector<double> lin, az;
  for (int i = 0; i < 400000; ++i) {
    g.advance(dt, kNaN, rng);
    lin.push_back(g.linear());
    az.push_back(g.azimuth_m());
  }
  for (const auto* x : {&lin, &az}) {
    for (std::size_t k : {1u, 3u}) {
      const auto r = ts::batch_means(*x, 50, [k](const std::vector<double>& b) { return ts::autocorrelation(b, k); });
      CHECK(std::abs(r.value - std::pow(rho, static_cast<double>(k))) < 5 * r.standard_error + 3.0 / 8000);
    }
  }
  const auto v = ts::batch_means(lin, 50, ts::variance);
  CHECK(std::abs(v.value - 90.25) < 5 * v.standard_error);
}
