// Purpose: tests of assoc.gnn: its assignment is the jointly most likely one, as brute-force enumeration of every gated one-to-one hypothesis finds, on random problems; P_D, clutter density and gate enter as the equations say.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

using namespace trackflow;

namespace {

std::unique_ptr<Associator> gnn(const std::string& yaml) { return test::make_part<Associator>("assoc.gnn", yaml); }

struct Problem {
  std::vector<PredictedMeasurement> predicted;
  std::vector<TrackView> tracks;
  std::vector<Detection> detections;
  Scan scan;
};

// n tracks and m detections in a 100 m cube, S diagonal with sigmas 3-10 m.
Problem random_problem(Rng& rng, int n, int m, double pd, double lambda) {
  Problem p;
  p.predicted.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    PredictedMeasurement& q = p.predicted[static_cast<size_t>(i)];
    q.z = Vec3(100 * rng.uniform(), 100 * rng.uniform(), 100 * rng.uniform());
    q.S = MeasCov::Zero(3, 3);
    for (int k = 0; k < 3; ++k) q.S(k, k) = std::pow(3 + 7 * rng.uniform(), 2);
    set_log_det(q);
  }
  for (int i = 0; i < n; ++i) {
    TrackView v;
    v.id = static_cast<std::uint64_t>(i + 1);
    v.predicted = &p.predicted[static_cast<size_t>(i)];
    p.tracks.push_back(v);
  }
  for (int j = 0; j < m; ++j) {
    Detection d;
    d.value = Vec3(100 * rng.uniform(), 100 * rng.uniform(), 100 * rng.uniform());
    d.covariance = MeasCov::Identity(3, 3);
    p.detections.push_back(d);
  }
  p.scan.sensor.frame = Frame::Cartesian;
  p.scan.detections = p.detections;
  p.scan.detection_probability = pd;
  p.scan.clutter_density = lambda;
  return p;
}

// -log likelihood ratio of the joint hypothesis `a` (detection of each track or -1), +inf if
// a pair lies outside its gate: the sum the associator must minimise.
double hypothesis_cost(const Problem& p, const std::vector<int>& a, double pg) {
  const double pd = p.scan.detection_probability, lambda = p.scan.clutter_density;
  const double gamma = chi_square_quantile(3, pg);
  double c = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] < 0) {
      c += -std::log(1 - pd * pg);
      continue;
    }
    const PredictedMeasurement& q = p.predicted[i];
    const Eigen::Vector3d nu = Eigen::Vector3d(p.detections[static_cast<size_t>(a[i])].value) - Eigen::Vector3d(q.z);
    const Eigen::Matrix3d S = q.S;
    const double nis = nu.dot(S.inverse() * nu);
    if (nis > gamma) return std::numeric_limits<double>::infinity();
    const double g = std::exp(-0.5 * nis) / std::sqrt(std::pow(2 * std::numbers::pi, 3) * S.determinant());
    c += -std::log(pd * g / lambda);
  }
  return c;
}

double brute_force_best(const Problem& p, double pg) {
  const size_t n = p.tracks.size(), m = p.detections.size();
  std::vector<int> a(n, -1);
  std::vector<char> used(m, 0);
  double best = std::numeric_limits<double>::infinity();
  std::function<void(size_t)> rec = [&](size_t i) {
    if (i == n) {
      best = std::min(best, hypothesis_cost(p, a, pg));
      return;
    }
    a[i] = -1;
    rec(i + 1);
    for (size_t j = 0; j < m; ++j) {
      if (used[j]) continue;
      used[j] = 1;
      a[i] = static_cast<int>(j);
      rec(i + 1);
      used[j] = 0;
    }
    a[i] = -1;
  };
  rec(0);
  return best;
}

}  // namespace

// 3 000 random problems of 1-5 tracks and 0-6 detections, dense enough that gates overlap: the
// associator's hypothesis costs what the best enumerated one costs, and is one-to-one.
TEST_CASE("gnn equals brute-force enumeration") {
  Rng rng(11);
  auto a = gnn("{ gate_probability: 0.999 }");
  int compared = 0, with_pairs = 0;
  for (int k = 0; k < 3000; ++k) {
    const int n = 1 + static_cast<int>(rng.uniform() * 5), m = static_cast<int>(rng.uniform() * 7);
    const double pd = 0.5 + 0.49 * rng.uniform(), lambda = std::pow(10.0, -6 + 3 * rng.uniform());
    Problem p = random_problem(rng, n, m, pd, lambda);
    // Half of the problems: detections near the tracks, so that hypotheses compete.
    if (k % 2 == 0)
      for (int j = 0; j < m && n > 0; ++j)
        p.detections[static_cast<size_t>(j)].value =
            p.predicted[static_cast<size_t>(j % n)].z + Vec3(8 * rng.normal(), 8 * rng.normal(), 8 * rng.normal());
    std::vector<int> out(static_cast<size_t>(n), -2);
    a->associate(p.tracks, p.scan, out);
    std::vector<char> used(static_cast<size_t>(m), 0);
    for (int j : out) {
      REQUIRE(j >= -1);
      REQUIRE(j < m);
      if (j >= 0) {
        REQUIRE_FALSE(used[static_cast<size_t>(j)]);
        used[static_cast<size_t>(j)] = 1;
        ++with_pairs;
      }
    }
    const double mine = hypothesis_cost(p, out, 0.999), best = brute_force_best(p, 0.999);
    REQUIRE(std::isfinite(mine));
    REQUIRE(mine == Approx(best).epsilon(1e-9).margin(1e-9));
    ++compared;
  }
  CHECK(compared == 3000);
  CHECK(with_pairs > 1500);  // the problems did make pairs
}

// A lone track and a detection at NIS 4: taken when the likelihood ratio P_D g / lambda beats
// the miss 1 - P_D P_G, refused when the clutter is dense enough, or the gate too small.
TEST_CASE("gnn weighs detection against miss") {
  Rng rng(3);
  Problem p = random_problem(rng, 1, 1, 0.9, 1e-6);
  p.predicted[0].z = Vec3(0, 0, 0);
  p.predicted[0].S = MeasCov::Identity(3, 3) * 25.0;
  set_log_det(p.predicted[0]);
  p.detections[0].value = Vec3(10, 0, 0);  // NIS 4
  std::vector<int> out(1);
  gnn("{}")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == 0);
  // g = exp(-2) / sqrt((2 pi)^3 25^3) = 6.87e-5: with lambda above P_D g / (1 - P_D P_G) = 5.7e-4 the miss wins.
  p.scan.clutter_density = 4e-4;
  gnn("{}")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == 0);
  p.scan.clutter_density = 8e-4;
  gnn("{}")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == -1);
  p.scan.clutter_density = 1e-6;
  gnn("{ gate_probability: 0.5 }")->associate(p.tracks, p.scan, out);  // chi2inv(0.5, 3) = 2.37 < 4
  CHECK(out[0] == -1);
  // A scan that states neither uses the parameters; without a clutter density it is refused.
  p.scan.clutter_density = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(gnn("{}")->associate(p.tracks, p.scan, out), DataError);
  gnn("{ clutter_density: 1e-6 1/m3 }")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == 0);
  // Parameters, when given, override what the scan states (a mismatched model of the sensor).
  p.scan.clutter_density = 1e-6;
  gnn("{ clutter_density: 8e-4 1/m3 }")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == -1);
  // P_D: with lambda = 4e-4 the detection wins at the scan's P_D 0.9 (above); an assumed P_D of 0.5
  // gives P_D g / (1 - P_D P_G) = 6.8e-5 < lambda: the miss wins.
  p.scan.clutter_density = 4e-4;
  gnn("{}")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == 0);
  gnn("{ detection_probability: 0.5 }")->associate(p.tracks, p.scan, out);
  CHECK(out[0] == -1);
}
