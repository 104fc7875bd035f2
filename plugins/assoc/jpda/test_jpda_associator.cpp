// Purpose: tests of assoc.jpda: its probabilities equal a brute-force enumeration of the joint events of the whole scan, with and without existence (JIPDA); above max_events the clusters go to belief propagation and are counted; through tracker.multi with init.existence and delete.existence two targets in clutter keep their tracks; existence-reading parts without an existence-keeping associator are refused.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

using namespace trackflow;

namespace {

struct Problem {
  std::vector<PredictedMeasurement> pred;
  std::vector<TrackView> tracks;
  std::vector<Detection> det;
  Scan scan;
};

// n tracks within a few sigma of each other in 2-D (planar), m detections around them.
Problem random_problem(Rng& rng, int n, int m) {
  Problem p;
  p.pred.resize(static_cast<size_t>(n));
  p.tracks.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    PredictedMeasurement& q = p.pred[static_cast<size_t>(i)];
    q.z = Eigen::Vector2d(8 * i + 3 * rng.normal(), 3 * rng.normal());
    q.S = MeasCov::Zero(2, 2);
    q.S(0, 0) = std::pow(2 + 3 * rng.uniform(), 2);
    q.S(1, 1) = std::pow(2 + 3 * rng.uniform(), 2);
    q.S(0, 1) = q.S(1, 0) = 0.3 * std::sqrt(q.S(0, 0) * q.S(1, 1));
    set_log_det(q);
    p.tracks[static_cast<size_t>(i)].id = static_cast<std::uint64_t>(i + 1);
    p.tracks[static_cast<size_t>(i)].predicted = &q;
    p.tracks[static_cast<size_t>(i)].existence = 0.2 + 0.8 * rng.uniform();
  }
  p.det.resize(static_cast<size_t>(m));
  for (Detection& d : p.det) {
    d.value = Eigen::Vector2d(8.0 * (n - 1) * rng.uniform() + 6 * rng.normal(), 6 * rng.normal());
    d.covariance = MeasCov::Identity(2, 2);
  }
  p.scan.sensor.frame = Frame::Planar;
  p.scan.detections = p.det;
  p.scan.detection_probability = 0.85;
  p.scan.clutter_density = 2e-3;
  return p;
}

// The joint events of the whole scan, enumerated: beta[i][j] (j = m: none), and with existence the
// posterior existence, from the factors of JIPDA (Musicki & Evans 2004) — r = 1 for JPDA.
struct Brute {
  std::vector<std::vector<double>> beta;
  std::vector<double> existence;
};
Brute brute_force(const Problem& p, double pg, double survival) {
  const int n = static_cast<int>(p.tracks.size()), m = static_cast<int>(p.det.size());
  const double pd = p.scan.detection_probability, lambda = p.scan.clutter_density;
  const double gamma = chi_square_quantile(2, pg);
  std::vector<std::vector<double>> l(static_cast<size_t>(n), std::vector<double>(static_cast<size_t>(m), 0.0));
  std::vector<double> r(static_cast<size_t>(n), 1.0), miss(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (survival > 0) r[i] = survival * p.tracks[i].existence;
    miss[i] = 1 - pd * pg * r[i];
    const Eigen::Matrix2d S = p.pred[i].S.topLeftCorner<2, 2>();
    for (int j = 0; j < m; ++j) {
      const Eigen::Vector2d nu = p.det[j].value.head<2>() - p.pred[i].z.head<2>();
      const double d2 = nu.dot(S.inverse() * nu);
      if (d2 <= gamma) l[i][j] = r[i] * pd * std::exp(-0.5 * d2) / (2 * std::numbers::pi * std::sqrt(S.determinant())) / lambda;
    }
  }
  Brute b;
  b.beta.assign(static_cast<size_t>(n), std::vector<double>(static_cast<size_t>(m) + 1, 0.0));
  std::vector<int> theta(static_cast<size_t>(n), -1);
  std::vector<char> used(static_cast<size_t>(m), 0);
  double total = 0;
  std::function<void(int, double)> walk = [&](int i, double w) {
    if (i == n) {
      total += w;
      for (int k = 0; k < n; ++k) b.beta[k][theta[k] < 0 ? m : theta[k]] += w;
      return;
    }
    theta[i] = -1;
    walk(i + 1, w * miss[i]);
    for (int j = 0; j < m; ++j) {
      if (used[j] || l[i][j] == 0) continue;
      used[j] = 1;
      theta[i] = j;
      walk(i + 1, w * l[i][j]);
      used[j] = 0;
    }
    theta[i] = -1;
  };
  walk(0, 1.0);
  for (auto& row : b.beta)
    for (double& x : row) x /= total;
  if (survival > 0) {
    for (int i = 0; i < n; ++i) {
      const double q = (1 - pd * pg) * r[i] / (1 - pd * pg * r[i]);
      double post = b.beta[i][m] * q;
      for (int j = 0; j < m; ++j) post += b.beta[i][j];
      b.existence.push_back(post);
      for (int j = 0; j < m; ++j) b.beta[i][j] /= post;
      b.beta[i][m] = b.beta[i][m] * q / post;
    }
  }
  return b;
}

void check_against_brute(const std::string& yaml, double survival) {
  auto a = test::make_part<Associator>("assoc.jpda", yaml);
  REQUIRE(a->probabilistic());
  CHECK(a->keeps_existence() == (survival > 0));
  Rng rng(11);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + trial % 4, m = trial % 6;
    Problem p = random_problem(rng, n, m);
    AssociationProbabilities out;
    out.clear(n);
    a->associate_probabilities(p.tracks, p.scan, out);
    const Brute b = brute_force(p, 0.99, survival);
    for (int i = 0; i < n; ++i) {
      std::vector<double> got(static_cast<size_t>(m), 0.0);
      for (const auto& e : out.of(i)) got[static_cast<size_t>(e.detection)] = e.probability;
      for (int j = 0; j < m; ++j) CHECK(got[j] == Approx(b.beta[i][j]).epsilon(1e-11).margin(1e-13));
      CHECK(out.none(i) == Approx(b.beta[i][m]).epsilon(1e-11).margin(1e-13));
      if (survival > 0) CHECK(out.existence(i) == Approx(b.existence[i]).epsilon(1e-11));
      else CHECK(std::isnan(out.existence(i)));
      ++checked;
    }
    CHECK(out.approximate_clusters == 0);
  }
  CHECK(checked > 500);
}

struct SetCollector : Component {
  std::vector<std::vector<TrackEstimate>> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.emplace_back(s.tracks.begin(), s.tracks.end()); }
};

}  // namespace

TEST_CASE("JPDA equals the enumeration of the joint events") {
  check_against_brute("{ gate_probability: 0.99 }", 0.0);
}

TEST_CASE("JIPDA and existence equal the enumeration") {
  check_against_brute("{ gate_probability: 0.99, survival_probability: 0.97 }", 0.97);
}

TEST_CASE("above max_events: belief propagation and counted") {
  auto exact = test::make_part<Associator>("assoc.jpda", "{}");
  auto lbp = test::make_part<Associator>("assoc.jpda", "{ max_events: 1 }");
  Rng rng(4);
  int approximate = 0;
  double worst = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Problem p = random_problem(rng, 3, 4);
    AssociationProbabilities a, b;
    a.clear(3);
    b.clear(3);
    exact->associate_probabilities(p.tracks, p.scan, a);
    lbp->associate_probabilities(p.tracks, p.scan, b);
    approximate += b.approximate_clusters;
    CHECK(a.approximate_clusters == 0);
    CHECK(b.exact_clusters == 0);  // every cluster with a pair has at least 2 events
    for (int i = 0; i < 3; ++i) {
      double sum = b.none(i);
      for (const auto& e : b.of(i)) sum += e.probability;
      CHECK(sum == Approx(1.0).epsilon(1e-12));
      worst = std::max(worst, std::fabs(a.none(i) - b.none(i)));
    }
  }
  CHECK(approximate > 50);
  CHECK(worst < 0.35);  // belief propagation's own error (association/jpda_lbp.hpp)
}

TEST_CASE("k-best JPDA is exact once k reaches the event count") {
  auto exact = test::make_part<Associator>("assoc.jpda", "{}");
  auto all = test::make_part<Associator>("assoc.jpda", "{ max_events: 1, approximation: k_best, k_best: 100000 }");
  auto few = test::make_part<Associator>("assoc.jpda", "{ max_events: 1, approximation: k_best, k_best: 3 }");
  Rng rng(8);
  int approximate = 0;
  for (int trial = 0; trial < 150; ++trial) {
    Problem p = random_problem(rng, 1 + trial % 4, 1 + trial % 5);
    const int n = static_cast<int>(p.tracks.size());
    AssociationProbabilities a, b, c;
    a.clear(n);
    b.clear(n);
    c.clear(n);
    exact->associate_probabilities(p.tracks, p.scan, a);
    all->associate_probabilities(p.tracks, p.scan, b);
    few->associate_probabilities(p.tracks, p.scan, c);
    approximate += b.approximate_clusters;
    CHECK(b.exact_clusters == 0);
    for (int i = 0; i < n; ++i) {
      CHECK(b.none(i) == Approx(a.none(i)).epsilon(1e-11).margin(1e-13));
      REQUIRE(b.of(i).size() == a.of(i).size());
      for (size_t k = 0; k < a.of(i).size(); ++k) {
        CHECK(b.of(i)[k].detection == a.of(i)[k].detection);
        CHECK(b.of(i)[k].probability == Approx(a.of(i)[k].probability).epsilon(1e-11).margin(1e-13));
      }
      double sum = c.none(i);
      for (const auto& e : c.of(i)) sum += e.probability;
      CHECK(sum == Approx(1.0).epsilon(1e-12));  // 3 events only: still a distribution
    }
  }
  CHECK(approximate > 100);
  CHECK_THROWS_WITH(test::make_part<Associator>("assoc.jpda", "{ k_best: 5 }"), Catch::Contains("approximation: k_best"));
}

TEST_CASE("JIPDA tracker: existence confirms and deletes") {
  auto n = test::make("tracker.multi",
                      "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, "
                      "associator: { type: assoc.jpda, survival_probability: 0.99 }, "
                      "initiator: { type: init.existence, max_speed: 50 m/s, initial_existence: 0.2 }, "
                      "deleter: { type: delete.existence, min_existence: 0.05 } }");
  SetCollector out;
  n->out.connect(&out.link, 1);
  test::start_run(*n);
  Rng rng(5);
  std::vector<Detection> det;
  for (int k = 0; k < 40; ++k) {
    const double t = k;
    det.clear();
    const Vec3 p1(0.0, -100.0 + 10.0 * t, 0.0), p2(30.0, 100.0 - 10.0 * t, 0.0);
    // Target 2 is gone after t = 25 s: its track's existence must fall and the track be deleted.
    for (const auto& [p, origin] : {std::pair{p1, 1u}, std::pair{p2, 2u}}) {
      if (origin == 2 && t > 25) continue;
      Detection d;
      d.value = p + 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = origin;
      det.push_back(d);
    }
    for (int c = 0; c < 5; ++c) {
      Detection d;
      d.value = Vec3(1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500);
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = kOriginClutter;
      det.push_back(d);
    }
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = det;
    s.detection_probability = 0.95;
    s.clutter_density = 5e-9;
    n->on_scan(s, 0);
  }
  auto confirmed = [](const std::vector<TrackEstimate>& set, std::uint32_t target) {
    int c = 0;
    for (const TrackEstimate& tr : set)
      c += (tr.status == TrackStatus::Confirmed || tr.status == TrackStatus::Coasting) && tr.estimate.target == target;
    return c;
  };
  for (int k = 8; k <= 25; ++k) {
    CHECK(confirmed(out.sets[k], 1) == 1);
    CHECK(confirmed(out.sets[k], 2) == 1);
    for (const TrackEstimate& tr : out.sets[k])
      if (tr.status == TrackStatus::Confirmed) CHECK(tr.existence > 0.95);
  }
  CHECK(confirmed(out.sets.back(), 1) == 1);
  CHECK(confirmed(out.sets.back(), 2) == 0);  // deleted once its existence fell
}

TEST_CASE("existence parts need an existence-keeping associator") {
  for (const char* assoc : {"assoc.gnn", "assoc.jpda", "assoc.pda"}) {
    INFO(assoc);
    try {
      test::make("tracker.multi", std::string("{ estimator: { type: filter.kalman },\n  associator: { type: ") + assoc +
                                      " },\n  initiator: { type: init.existence, max_speed: 1 m/s },\n"
                                      "  deleter: { type: delete.misses } }");
      FAIL("init.existence without existence accepted");
    } catch (const ConfigError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find("existence") != std::string::npos);
      CHECK(e.where().line == 3);
    }
  }
  CHECK_NOTHROW(test::make("tracker.multi",
                           "{ estimator: { type: filter.kalman }, associator: { type: assoc.pda, survival_probability: 0.9 }, "
                           "initiator: { type: init.existence, max_speed: 1 m/s }, deleter: { type: delete.existence } }"));
}
