// Purpose: GatedPairs (grid pre-gate) gives exactly the pairs and NIS of testing every track against every detection; PointGrid lists every point in a box.
#include "association/gated_pairs.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

using namespace trackflow;
using trackflow::association::GatedPair;
using trackflow::association::GatedPairs;
using trackflow::association::PointGrid;
using trackflow::association::PredictedGate;

namespace {

struct World {
  std::vector<PredictedMeasurement> predicted;
  std::vector<TrackView> views;
  std::vector<Detection> detections;
  Scan scan;
};

// Tracks with random S (some with huge gates, some tiny), detections clustered and spread.
World random_world(std::mt19937_64& rng, Frame frame) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> count(0, 40);
  World w;
  const int n = count(rng), m = count(rng);
  const double spread = u(rng) < 0.2 ? 1e-3 : 1000.0 * u(rng);  // sometimes every point nearly together
  w.predicted.resize(static_cast<std::size_t>(n));
  for (auto& p : w.predicted) {
    p.z = MeasVec::Zero(3);
    for (int k = 0; k < 3; ++k) p.z(k) = spread * u(rng);
    if (frame == Frame::Spherical) p.z(1) = 6.0 * u(rng) - 3.0;
    Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const double scale = std::pow(10.0, 4.0 * u(rng) - 1.0);
    const Eigen::Matrix3d S = scale * (A * A.transpose() + 0.01 * Eigen::Matrix3d::Identity());
    p.S = S;
    set_log_det(p);
  }
  for (int j = 0; j < m; ++j) {
    Detection d;
    d.value = MeasVec::Zero(3);
    for (int k = 0; k < 3; ++k) d.value(k) = spread * u(rng);
    if (frame == Frame::Spherical) d.value(1) = 6.0 * u(rng) - 3.0;
    d.covariance = MeasCov::Identity(3, 3);
    w.detections.push_back(d);
  }
  w.views.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    w.views[static_cast<std::size_t>(i)].predicted = u(rng) < 0.05 ? nullptr : &w.predicted[static_cast<std::size_t>(i)];
  w.scan.sensor.frame = frame;
  w.scan.detections = w.detections;
  return w;
}

// Every pair by direct test, sorted by (track, detection).
std::vector<std::tuple<int, int, double>> all_pairs(const World& w, double pg) {
  std::vector<std::tuple<int, int, double>> out;
  PredictedGate g;
  for (std::size_t i = 0; i < w.views.size(); ++i) {
    if (!w.views[i].predicted || !g.set(*w.views[i].predicted, w.scan.sensor.frame)) continue;
    const double gamma = chi_square_quantile(g.dim(), pg);
    for (std::size_t j = 0; j < w.detections.size(); ++j) {
      const double nis = g.nis(w.detections[j].value);
      if (nis <= gamma) out.emplace_back(static_cast<int>(i), static_cast<int>(j), nis);
    }
  }
  return out;
}

}  // namespace

TEST_CASE("grid pre-gate = all-pairs test: same pairs, same NIS") {
  std::mt19937_64 rng(4);
  std::size_t total = 0;
  for (Frame frame : {Frame::Cartesian, Frame::Spherical}) {
    GatedPairs gated(0.99);
    for (int k = 0; k < 1500; ++k) {
      const World w = random_world(rng, frame);
      std::vector<std::tuple<int, int, double>> got;
      for (const GatedPair& p : gated.find(w.views, w.scan)) got.emplace_back(p.track, p.detection, p.nis);
      std::sort(got.begin(), got.end());
      REQUIRE(got == all_pairs(w, 0.99));
      total += got.size();
    }
  }
  CHECK(total > 10000);  // the worlds do gate many pairs
}

TEST_CASE("PointGrid lists every point inside a box, once") {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PointGrid grid;
  for (int k = 0; k < 500; ++k) {
    std::vector<Eigen::Vector2d> pts(static_cast<std::size_t>(k % 60));
    for (auto& p : pts) p = Eigen::Vector2d(100 * u(rng), (k % 3 ? 100 : 1e-6) * u(rng));
    grid.build(pts, k % 5 == 0 ? 0.0 : 50.0 * u(rng) + 1e-3);
    CHECK(grid.cells() <= 2 * static_cast<int>(pts.size()) + 16);
    const Eigen::Vector2d a(120 * u(rng) - 10, 120 * u(rng) - 10), b(120 * u(rng) - 10, 120 * u(rng) - 10);
    const Eigen::Vector2d lo = a.cwiseMin(b), hi = a.cwiseMax(b);
    std::vector<int> seen(pts.size(), 0);
    grid.for_each_candidate(lo, hi, [&](int i) { ++seen[static_cast<std::size_t>(i)]; });
    for (std::size_t i = 0; i < pts.size(); ++i) {
      CHECK(seen[i] <= 1);
      const bool inside = (pts[i].array() >= lo.array()).all() && (pts[i].array() <= hi.array()).all();
      if (inside) CHECK(seen[i] == 1);
    }
  }
}
