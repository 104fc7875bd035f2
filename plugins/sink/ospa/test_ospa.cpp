// Purpose: tests of OSPA as metrics::Gospa computes it for sink.ospa: against every permutation on random small sets, hand-worked cases from the definition, and the metric axioms.
#include "scoring/gospa.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

using trackflow::metrics::Gospa;
using Points = std::vector<Eigen::Vector2d>;

namespace {

// Schuhmacher, Vo and Vo's definition read literally: m = min(|X|, |Y|), n = max, the minimum over
// every permutation pi of the larger set's indices of sum_{i <= m} min(c, d(x_i, y_pi(i)))^p, plus
// c^p (n - m), divided by n, to the power 1/p; 0 for two empty sets.
double brute_force_ospa(const Points& x, const Points& y, double c, double p) {
  const Points& small = x.size() <= y.size() ? x : y;
  const Points& large = x.size() <= y.size() ? y : x;
  const std::size_t m = small.size(), n = large.size();
  if (n == 0) return 0.0;
  std::vector<std::size_t> pi(n);
  std::iota(pi.begin(), pi.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    double sum = 0.0;
    for (std::size_t i = 0; i < m; ++i) sum += std::pow(std::min(c, (small[i] - large[pi[i]]).norm()), p);
    best = std::min(best, sum);
  } while (std::next_permutation(pi.begin(), pi.end()));
  return std::pow((best + std::pow(c, p) * static_cast<double>(n - m)) / static_cast<double>(n), 1.0 / p);
}

double ospa(const Points& x, const Points& y, double c, double p) { return Gospa(c, p).evaluate(x, y).ospa; }

// Up to 6 points in a 20 m square, so that with c of 2-12 m some pairs are closer than c and some not.
Points random_set(std::mt19937& rng, int max_size = 6) {
  std::uniform_int_distribution<int> size(0, max_size);
  std::uniform_real_distribution<double> coord(0.0, 20.0);
  Points out(static_cast<std::size_t>(size(rng)));
  for (auto& pt : out) pt = Eigen::Vector2d(coord(rng), coord(rng));
  return out;
}

Points set(std::initializer_list<double> xs) {
  Points out;
  for (double x : xs) out.emplace_back(x, 0.0);
  return out;
}

}  // namespace

TEST_CASE("OSPA equals the brute force over all permutations") {
  std::mt19937 rng(20080801);
  std::uniform_real_distribution<double> cutoff(2.0, 12.0);
  const double orders[] = {1.0, 2.0, 3.0, 1.5};
  int empty_cases = 0;
  for (int k = 0; k < 1500; ++k) {
    const Points x = random_set(rng), y = random_set(rng);
    const double c = cutoff(rng), p = orders[k % 4];
    empty_cases += x.empty() || y.empty();
    const auto r = Gospa(c, p).evaluate(x, y);
    const double expected = brute_force_ospa(x, y, c, p);
    INFO("case " << k << ": |X| = " << x.size() << ", |Y| = " << y.size() << ", c = " << c << ", p = " << p);
    CHECK(r.ospa == Approx(expected).epsilon(1e-12).margin(1e-12));
    // The two terms add up to the p-th power.
    CHECK(r.ospa_localisation + r.ospa_cardinality == Approx(std::pow(expected, p)).epsilon(1e-12).margin(1e-12));
  }
  CHECK(empty_cases > 100);  // sizes 0..6: about a quarter of the cases have an empty set
}

TEST_CASE("hand-worked OSPA cases from the definition") {
  CHECK(ospa(set({}), set({}), 10.0, 1.0) == 0.0);                  // both empty
  CHECK(ospa(set({0}), set({}), 10.0, 1.0) == 10.0);               // exactly one empty: c
  CHECK(ospa(set({}), set({0, 5, 9}), 10.0, 3.0) == Approx(10.0));  // c whatever the sizes and p
  CHECK(ospa(set({0}), set({3}), 10.0, 1.0) == 3.0);
  CHECK(ospa(set({0}), set({30}), 10.0, 1.0) == 10.0);        // a pair beyond c costs c
  CHECK(ospa(set({0}), set({0, 100}), 10.0, 1.0) == 5.0);     // (0 + 10) / 2
  CHECK(ospa(set({0}), set({0, 100}), 10.0, 2.0) == Approx(std::sqrt(50.0)));  // ((0 + 100) / 2)^(1/2)
  // Two truths, two tracks: the crossed pairing (1 + 1) beats the straight one (9 + 11, clipped).
  CHECK(ospa(set({0, 10}), set({11, 1}), 10.0, 1.0) == Approx(1.0));
}

TEST_CASE("OSPA terms: localisation and cardinality over n") {
  // X = {0}, Y = {4, 100}, c = 10, p = 2: n = 2, m = 1; localisation 16 / 2, cardinality 100 / 2.
  const auto r = Gospa(10.0, 2.0).evaluate(set({0}), set({4, 100}));
  CHECK(r.ospa_localisation == Approx(8.0));
  CHECK(r.ospa_cardinality == Approx(50.0));
  CHECK(r.ospa == Approx(std::sqrt(58.0)));
  // Both empty: no terms.
  const auto e = Gospa(10.0, 2.0).evaluate(set({}), set({}));
  CHECK(e.ospa_localisation == 0.0);
  CHECK(e.ospa_cardinality == 0.0);
}

TEST_CASE("OSPA is a metric: identity, symmetry, triangle inequality") {
  std::mt19937 rng(56);
  const double orders[] = {1.0, 2.0, 3.0};
  for (int k = 0; k < 600; ++k) {
    const Points x = random_set(rng, 5), y = random_set(rng, 5), z = random_set(rng, 5);
    const double c = 6.0, p = orders[k % 3];
    INFO("case " << k << ", p = " << p);
    CHECK(ospa(x, x, c, p) == Approx(0.0).margin(1e-12));
    const double xy = ospa(x, y, c, p), yx = ospa(y, x, c, p);
    CHECK(xy == Approx(yx).epsilon(1e-12).margin(1e-12));
    if (x.size() != y.size()) CHECK(xy > 0.0);
    CHECK(ospa(x, z, c, p) <= xy + ospa(y, z, c, p) + 1e-9);
    CHECK(xy <= c);  // bounded by c
  }
}
