// Purpose: Gospa against enumeration of both of GOSPA's definitions, hand-worked sets and bad parameters.
#include "scoring/gospa.hpp"

#include "assignment/one_to_one_check.hpp"
#include "gospa_brute_force.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using trackflow::assignment::test::require_one_to_one;
using trackflow::metrics::Gospa;
using trackflow::metrics::GospaResult;
using trackflow::metrics::test::InjectionGospa;
using trackflow::metrics::test::PartialAssignmentGospa;

namespace {

using Points2 = std::vector<Eigen::Vector2d>;
using Points3 = std::vector<Eigen::Vector3d>;

std::vector<int> copy_of(std::span<const int> s) { return {s.begin(), s.end()}; }

bool close(double a, double b, double rel = 1e-12) { return std::abs(a - b) <= rel * std::max(1.0, std::abs(b)); }

template <int Dim>
std::vector<Eigen::Matrix<double, Dim, 1>> random_points(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> box(0.0, 10.0);
  std::vector<Eigen::Matrix<double, Dim, 1>> points(static_cast<std::size_t>(n));
  for (auto& x : points)
    for (int k = 0; k < Dim; ++k) x[k] = box(rng);
  return points;
}

struct Coverage {
  int problems = 0, alpha_two = 0, empty_truth = 0, empty_tracks = 0, clipped_pairs = 0;
};

// One random problem checked against the enumerations; returns nothing, REQUIREs everything.
template <int Dim>
void check_against_enumeration(std::mt19937_64& rng, Coverage& coverage) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int nx = static_cast<int>(rng() % 7), ny = static_cast<int>(rng() % 7);
  const auto truth = random_points<Dim>(rng, nx);
  const auto tracks = random_points<Dim>(rng, ny);
  const double c = 0.5 + 7.5 * unit(rng);
  const double orders[] = {1.0, 2.0, 3.0, 1.5};
  const double p = orders[rng() % 4];
  const double alphas[] = {2.0, 2.0, 1.0, 0.5, 2.0 * (1.0 - unit(rng))};  // the last in (0, 2]
  const double alpha = alphas[rng() % 5];
  INFO(Dim << "-D, |X| " << nx << ", |Y| " << ny << ", c " << c << ", p " << p << ", alpha " << alpha);

  Gospa gospa(c, p, alpha);
  const GospaResult r = gospa.evaluate(truth, tracks);
  const double cp = std::pow(c, p);

  // Definition 1 (Eq. 1) by enumerating injections, for every alpha.
  InjectionGospa<Dim> injections;
  REQUIRE(close(r.gospa_pow_p, injections.pow_p(truth, tracks, c, p, cp / alpha)));
  REQUIRE(close(std::pow(r.gospa, p), r.gospa_pow_p, 1e-10));
  // OSPA from the same enumeration, divided by the larger size.
  const int larger = std::max(nx, ny);
  const double ospa = larger == 0 ? 0.0 : std::pow(injections.pow_p(truth, tracks, c, p, cp) / larger, 1.0 / p);
  REQUIRE(close(r.ospa, ospa, 1e-10));
  REQUIRE(r.ospa <= c * (1 + 1e-12));
  // The metric is symmetric.
  Gospa swapped(c, p, alpha);
  REQUIRE(close(swapped.evaluate(tracks, truth).gospa_pow_p, r.gospa_pow_p));

  // The reported pairs: distinct tracks, each closer than c.
  REQUIRE(r.track_for_truth.size() == static_cast<std::size_t>(nx));
  const int detected = require_one_to_one(r.track_for_truth, ny);
  double localisation = 0.0;
  for (int i = 0; i < nx; ++i) {
    const int j = r.track_for_truth[static_cast<std::size_t>(i)];
    if (j < 0) continue;
    const double d = (truth[static_cast<std::size_t>(i)] - tracks[static_cast<std::size_t>(j)]).norm();
    REQUIRE(d < c);
    localisation += std::pow(d, p);
  }
  coverage.clipped_pairs += std::min(nx, ny) - detected;

  if (alpha == 2.0) {
    // Proposition 1 (Eq. 2) by enumerating partial assignments, and the decomposition.
    ++coverage.alpha_two;
    PartialAssignmentGospa<Dim> partial;
    REQUIRE(close(r.gospa_pow_p, partial.pow_p(truth, tracks, c, p)));
    REQUIRE(r.decomposition.has_value());
    const auto& parts = *r.decomposition;
    REQUIRE(close(parts.localisation + parts.missed + parts.false_tracks, r.gospa_pow_p));
    REQUIRE(close(parts.localisation, localisation));
    REQUIRE(parts.detected == detected);
    REQUIRE(parts.missed_count == nx - detected);
    REQUIRE(parts.false_count == ny - detected);
    REQUIRE(close(parts.missed, cp / 2 * (nx - detected)));
    REQUIRE(close(parts.false_tracks, cp / 2 * (ny - detected)));
  } else {
    REQUIRE_FALSE(r.decomposition.has_value());
  }
  ++coverage.problems;
  coverage.empty_truth += nx == 0 ? 1 : 0;
  coverage.empty_tracks += ny == 0 ? 1 : 0;
}

}  // namespace

TEST_CASE("equals enumeration of Eq. 1 and Eq. 2 on 4000 sets up to 6x6", "[gospa]") {
  std::mt19937_64 rng(1601055850);
  Coverage coverage;
  for (int n = 0; n < 4000; ++n) {
    if (n % 2 == 0)
      check_against_enumeration<2>(rng, coverage);
    else
      check_against_enumeration<3>(rng, coverage);
  }
  CHECK(coverage.problems == 4000);
  CHECK(coverage.alpha_two >= 1400);
  CHECK(coverage.empty_truth >= 300);
  CHECK(coverage.empty_tracks >= 300);
  CHECK(coverage.clipped_pairs >= 1000);  // the cut-off really decides pairs
  WARN("GOSPA: " << coverage.problems << " set pairs compared with enumeration, " << coverage.alpha_two
                 << " with alpha = 2 also against the partial assignments");
}

TEST_CASE("hand-worked: a missed target", "[gospa]") {
  // c = 5, p = 2, alpha = 2. Truths (0,0) and (10,0), one track (1,0). Clipped costs: 1^2 = 1 to
  // the first truth, min(9, 5)^2 = 25 to the second; the track takes the first (1), the second
  // truth is missed: GOSPA^2 = 1 + 25/2 = 13.5, GOSPA = sqrt(13.5) = 3.67423...
  // OSPA: n = 2, ((1 + 25) / 2)^(1/2) = sqrt(13) = 3.60555...
  Gospa gospa(5.0, 2.0, 2.0);
  const GospaResult r = gospa.evaluate(Points2{{0, 0}, {10, 0}}, Points2{{1, 0}});
  CHECK(r.gospa_pow_p == 13.5);
  CHECK(r.gospa == Approx(3.6742346141747673).epsilon(1e-15));
  CHECK(r.ospa == Approx(3.605551275463989).epsilon(1e-15));
  REQUIRE(r.decomposition);
  CHECK(r.decomposition->localisation == 1.0);
  CHECK(r.decomposition->missed == 12.5);
  CHECK(r.decomposition->false_tracks == 0.0);
  CHECK(r.decomposition->missed_count == 1);
  CHECK(r.decomposition->false_count == 0);
  CHECK(copy_of(r.track_for_truth) == std::vector<int>{0, -1});
}

TEST_CASE("hand-worked: a pair beyond the cut-off is missed plus false", "[gospa]") {
  // c = 3, p = 1: truth (0,0), track (10,0). min(10, 3) = 3 = GOSPA = OSPA; for alpha = 2 that
  // is one missed (3/2) and one false (3/2), no localisation.
  Gospa gospa(3.0, 1.0, 2.0);
  const GospaResult r = gospa.evaluate(Points2{{0, 0}}, Points2{{10, 0}});
  CHECK(r.gospa == 3.0);
  CHECK(r.ospa == 3.0);
  REQUIRE(r.decomposition);
  CHECK(r.decomposition->localisation == 0.0);
  CHECK(r.decomposition->missed == 1.5);
  CHECK(r.decomposition->false_tracks == 1.5);
  CHECK(r.decomposition->detected == 0);
  CHECK(copy_of(r.track_for_truth) == std::vector<int>{-1});
}

TEST_CASE("hand-worked: the cut-off changes the optimal pairs", "[gospa]") {
  // Truths (0,0), (2,0); tracks (1.1,0), (3.5,0). Distances: t0-k0 1.1, t0-k1 3.5, t1-k0 0.9,
  // t1-k1 1.5. p = 1, alpha = 2.
  const Points2 truth{{0, 0}, {2, 0}}, tracks{{1.1, 0}, {3.5, 0}};
  SECTION("c = 10: t0-k0 + t1-k1 = 2.6 beats t0-k1 + t1-k0 = 4.4 (the greedy closest pair first)") {
    Gospa gospa(10.0, 1.0, 2.0);
    const GospaResult r = gospa.evaluate(truth, tracks);
    CHECK(r.gospa == Approx(2.6).epsilon(1e-15));
    CHECK(r.ospa == Approx(1.3).epsilon(1e-15));  // 2.6 / 2
    CHECK(copy_of(r.track_for_truth) == std::vector<int>{0, 1});
    CHECK(r.decomposition->missed_count == 0);
  }
  SECTION("c = 1.2: clipped t0-k0 + t1-k1 = 1.1 + 1.2 = 2.3 loses to t0-k1 + t1-k0 = 1.2 + 0.9 = 2.1") {
    // Only t1-k0 (0.9) is closer than c: localisation 0.9, t0 missed 0.6, k1 false 0.6.
    Gospa gospa(1.2, 1.0, 2.0);
    const GospaResult r = gospa.evaluate(truth, tracks);
    CHECK(r.gospa == Approx(2.1).epsilon(1e-15));
    CHECK(copy_of(r.track_for_truth) == std::vector<int>{-1, 0});
    REQUIRE(r.decomposition);
    CHECK(r.decomposition->localisation == Approx(0.9).epsilon(1e-15));
    CHECK(r.decomposition->missed == Approx(0.6).epsilon(1e-15));
    CHECK(r.decomposition->false_tracks == Approx(0.6).epsilon(1e-15));
  }
}

TEST_CASE("hand-worked: empty sets", "[gospa]") {
  // c = 2, p = 2, alpha = 2: no truth, three tracks: GOSPA^2 = 3 * 2^2 / 2 = 6, all false;
  // OSPA = c = 2. Two empty sets: 0 and 0.
  Gospa gospa(2.0, 2.0, 2.0);
  const GospaResult r = gospa.evaluate(Points3{}, Points3{{0, 0, 0}, {1, 1, 1}, {5, 5, 5}});
  CHECK(r.gospa_pow_p == 6.0);
  CHECK(r.gospa == Approx(std::sqrt(6.0)).epsilon(1e-15));
  CHECK(r.ospa == 2.0);
  REQUIRE(r.decomposition);
  CHECK(r.decomposition->false_tracks == 6.0);
  CHECK(r.decomposition->false_count == 3);
  CHECK(r.track_for_truth.empty());
  const GospaResult none = gospa.evaluate(Points3{}, Points3{});
  CHECK(none.gospa == 0.0);
  CHECK(none.ospa == 0.0);
  // Truths but no tracks: all missed.
  const GospaResult missed = gospa.evaluate(Points3{{0, 0, 0}}, Points3{});
  CHECK(missed.gospa_pow_p == 2.0);
  CHECK(copy_of(missed.track_for_truth) == std::vector<int>{-1});
}

TEST_CASE("hand-worked: alpha = 1 and p = 3 in 3-D", "[gospa]") {
  // alpha = 1, p = 1, c = 4: truth (0,0,0); tracks (3,4,0) at 5 -> clipped 4, and (0,0,1) at 1.
  // Best: the near track (1), the far one left over at c / alpha = 4: GOSPA = 5. OSPA = (1 + 4) / 2.
  Gospa alpha_one(4.0, 1.0, 1.0);
  const GospaResult a = alpha_one.evaluate(Points3{{0, 0, 0}}, Points3{{3, 4, 0}, {0, 0, 1}});
  CHECK(a.gospa == 5.0);
  CHECK(a.ospa == 2.5);
  CHECK_FALSE(a.decomposition.has_value());
  CHECK(copy_of(a.track_for_truth) == std::vector<int>{1});
  // p = 3, c = 10: truth (1,2,2), track (0,0,0) at 3: GOSPA^3 = 27, GOSPA = 3.
  Gospa cubic(10.0, 3.0, 2.0);
  const GospaResult b = cubic.evaluate(Points3{{1, 2, 2}}, Points3{{0, 0, 0}});
  CHECK(b.gospa_pow_p == Approx(27.0).epsilon(1e-15));
  CHECK(b.gospa == Approx(3.0).epsilon(1e-15));
}

TEST_CASE("reserved storage is reused, not reallocated", "[gospa]") {
  std::mt19937_64 rng(3);
  Gospa gospa(4.0, 2.0);
  gospa.reserve(6, 6);
  const int* storage = nullptr;
  for (int n = 0; n < 100; ++n) {
    const auto truth = random_points<2>(rng, 1 + static_cast<int>(rng() % 6));
    const auto tracks = random_points<2>(rng, static_cast<int>(rng() % 7));
    const GospaResult r = gospa.evaluate(truth, tracks);
    if (!storage) storage = r.track_for_truth.data();
    REQUIRE(r.track_for_truth.data() == storage);
  }
}

TEST_CASE("bad parameters and positions are refused", "[gospa]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(Gospa(0.0, 2.0), Catch::Contains("cut-off"));
  CHECK_THROWS_WITH(Gospa(nan, 2.0), Catch::Contains("cut-off"));
  CHECK_THROWS_WITH(Gospa(inf, 2.0), Catch::Contains("cut-off"));
  CHECK_THROWS_WITH(Gospa(1.0, 0.5), Catch::Contains("order p"));
  CHECK_THROWS_WITH(Gospa(1.0, nan), Catch::Contains("order p"));
  CHECK_THROWS_WITH(Gospa(1.0, 2.0, 0.0), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(Gospa(1.0, 2.0, 2.5), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(Gospa(1.0, 2.0, nan), Catch::Contains("alpha"));
  Gospa gospa(1.0, 2.0);
  CHECK_THROWS_WITH(gospa.evaluate(Points2{{0, nan}}, Points2{{0, 0}}), Catch::Contains("truth position 0"));
  CHECK_THROWS_WITH(gospa.evaluate(Points2{{0, 0}}, Points2{{0, 0}, {inf, 0}}),
                    Catch::Contains("track position 1"));
  CHECK(gospa.evaluate(Points2{{0, 0}}, Points2{{0.5, 0}}).gospa == 0.5);  // still usable
}
