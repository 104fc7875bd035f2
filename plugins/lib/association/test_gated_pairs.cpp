// Purpose: GatedPairs (grid pre-gate, Cartesian and spherical) gives exactly the pairs and NIS of testing every track against every detection; PointGrid and SphericalGrid list every point in a box.
#include "association/gated_pairs.hpp"
#include "association/spherical_grid.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <tuple>
#include <vector>

using namespace trackflow;
using trackflow::association::GatedPair;
using trackflow::association::GatedPairs;
using trackflow::association::PointGrid;
using trackflow::association::PredictedGate;
using trackflow::association::SphericalGrid;

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
  for (Frame frame : {Frame::Cartesian, Frame::Spherical, Frame::Planar}) {
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

namespace {

// Spherical worlds built to hit the grid's edge cases: tracks and detections near the azimuth seam
// (and azimuths given outside (-pi, pi]: [0, 2 pi) or a turn off), near the zenith and the sensor
// (huge azimuth variance: a gate wider than the circle), tiny and huge S, correlated S, measurements
// of 2 (range, azimuth), 3 or 4 values (range rate last), clustered detections, a few non-finite.
World spherical_world(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> count(0, 60);
  constexpr double pi = std::numbers::pi;
  World w;
  const int n = count(rng), m = count(rng);
  const int dim = u(rng) < 0.15 ? 2 : u(rng) < 0.3 ? 4 : 3;
  const double range_hi = u(rng) < 0.2 ? 50.0 : 2e5 * u(rng) + 1.0;
  const bool seam = u(rng) < 0.5, zenith = u(rng) < 0.2;
  auto value = [&](MeasVec& v) {
    v = MeasVec::Zero(dim);
    v(0) = range_hi * u(rng);
    v(1) = seam ? pi + 0.05 * (2.0 * u(rng) - 1.0) : 2.0 * pi * u(rng) - pi;
    const double turn = u(rng);
    if (turn < 0.2) v(1) += 2.0 * pi;  // the same direction, a turn off
    else if (turn < 0.3) v(1) -= 2.0 * pi;
    else v(1) = wrap_angle(v(1));
    if (dim >= 3) v(2) = zenith ? pi / 2 - 0.02 * u(rng) : 1.2 * u(rng) - 0.1;
    if (dim == 4) v(3) = 300.0 * (2.0 * u(rng) - 1.0);
  };
  w.predicted.resize(static_cast<std::size_t>(n));
  for (auto& p : w.predicted) {
    value(p.z);
    // Per-axis standard deviations from 1e-6 to 1e3 of each axis' unit, sometimes one track's
    // azimuth sigma of radians (near the sensor or the zenith), with a random correlation.
    Eigen::VectorXd sigma(dim);
    for (int k = 0; k < dim; ++k) sigma(k) = std::pow(10.0, 9.0 * u(rng) - 6.0) * (k == 1 || k == 2 ? 1e-3 : 1.0);
    if (u(rng) < 0.15) sigma(1) = 0.5 + 3.0 * u(rng);
    const Eigen::MatrixXd A = Eigen::MatrixXd::Random(dim, dim);
    Eigen::MatrixXd C = A * A.transpose() + 0.05 * Eigen::MatrixXd::Identity(dim, dim);
    const Eigen::VectorXd d = C.diagonal().cwiseSqrt().cwiseInverse();
    C = d.asDiagonal() * C * d.asDiagonal();  // a correlation matrix
    p.S = sigma.asDiagonal() * C * sigma.asDiagonal();
    set_log_det(p);
  }
  for (int j = 0; j < m; ++j) {
    Detection det;
    if (n > 0 && u(rng) < 0.5) {
      // Near a track's prediction, within a few of its sigmas (so that many pairs gate).
      const PredictedMeasurement& p = w.predicted[static_cast<std::size_t>(std::uniform_int_distribution<int>(0, n - 1)(rng))];
      const Eigen::LLT<MeasCov> llt(p.S);
      MeasVec e = MeasVec::Zero(dim);
      std::normal_distribution<double> g(0.0, 1.5);
      for (int k = 0; k < dim; ++k) e(k) = g(rng);
      det.value = p.z + (llt.info() == Eigen::Success ? MeasVec(llt.matrixL() * e) : e);
      if (u(rng) < 0.3) det.value(1) = wrap_angle(det.value(1));
    } else {
      value(det.value);
    }
    if (u(rng) < 0.02) det.value(std::uniform_int_distribution<int>(0, dim - 1)(rng)) = u(rng) < 0.5 ? NAN : INFINITY;
    det.covariance = MeasCov::Identity(dim, dim);
    w.detections.push_back(det);
  }
  w.views.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    w.views[static_cast<std::size_t>(i)].predicted = u(rng) < 0.05 ? nullptr : &w.predicted[static_cast<std::size_t>(i)];
  w.scan.sensor.frame = Frame::Spherical;
  w.scan.detections = w.detections;
  return w;
}

}  // namespace

TEST_CASE("spherical grid pre-gate = all pairs in the same order") {
  std::mt19937_64 rng(21);
  std::size_t total = 0, seam_pairs = 0, wide = 0;
  GatedPairs gated(0.999);
  for (int k = 0; k < 4000; ++k) {
    const World w = spherical_world(rng);
    std::vector<std::tuple<int, int, double>> got;
    for (const GatedPair& p : gated.find(w.views, w.scan)) {
      got.emplace_back(p.track, p.detection, p.nis);
      // The likelihood is the gate's, to the bit.
      PredictedGate g;
      g.set(*w.views[static_cast<std::size_t>(p.track)].predicted, Frame::Spherical);
      REQUIRE(p.log_likelihood == g.log_likelihood(p.nis));
      const double dz = w.detections[static_cast<std::size_t>(p.detection)].value(1) -
                        w.predicted[static_cast<std::size_t>(p.track)].z(1);
      if (std::fabs(wrap_angle(w.detections[static_cast<std::size_t>(p.detection)].value(1)) -
                    wrap_angle(w.predicted[static_cast<std::size_t>(p.track)].z(1))) > std::numbers::pi)
        ++seam_pairs;  // the pair gates only across the seam
      if (std::fabs(dz) > 1.0) ++wide;
    }
    // Unsorted: the order itself must be the all-pairs test's (by track, then detection).
    REQUIRE(got == all_pairs(w, 0.999));
    total += got.size();
  }
  CHECK(total > 20000);
  CHECK(seam_pairs > 500);  // the worlds do gate across the seam
  CHECK(wide > 500);        // and with gates wider than a radian or a turn off
}

TEST_CASE("SphericalGrid lists every point in a box once") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr double pi = std::numbers::pi;
  SphericalGrid grid;
  std::size_t listed = 0, inside_total = 0;
  for (int k = 0; k < 3000; ++k) {
    const int axes = k % 3 == 0 ? 2 : 3;
    std::vector<Eigen::Vector3d> pts(static_cast<std::size_t>(k % 80));
    const bool narrow = k % 7 == 0;  // every azimuth in a sliver (the two seam pieces meet in one column)
    for (auto& p : pts) p = Eigen::Vector3d(1e4 * u(rng), narrow ? 3.0 + 0.1 * u(rng) : 8.0 * u(rng) - 4.0, k % 4 ? u(rng) : 1e-9 * u(rng));
    const Eigen::Vector3d cell(k % 5 == 0 ? 0.0 : 3e3 * u(rng) + 1e-3, 2.0 * u(rng), 0.5 * u(rng));
    grid.build(pts, axes, cell);
    CHECK(grid.cells() <= 2 * static_cast<int>(pts.size()) + 16);
    const Eigen::Vector3d centre(1.2e4 * u(rng) - 1e3, 12.0 * u(rng) - 6.0, 1.4 * u(rng) - 0.2);
    Eigen::Vector3d half(3e3 * u(rng), u(rng) < 0.1 ? 4.0 * u(rng) + 2.0 : 0.8 * u(rng), 0.4 * u(rng));
    if (k % 11 == 0) half(0) = INFINITY;
    std::vector<int> seen(pts.size(), 0);
    grid.for_each_candidate(centre, half, [&](int i) { ++seen[static_cast<std::size_t>(i)]; });
    for (std::size_t i = 0; i < pts.size(); ++i) {
      REQUIRE(seen[i] <= 1);
      listed += static_cast<std::size_t>(seen[i]);
      const Eigen::Vector3d& p = pts[i];
      const bool inside = std::fabs(p(0) - centre(0)) <= half(0) && std::fabs(wrap_angle(p(1) - centre(1))) <= half(1) &&
                          (axes == 2 || std::fabs(p(2) - centre(2)) <= half(2));
      if (inside) {
        REQUIRE(seen[i] == 1);
        ++inside_total;
      }
    }
  }
  CHECK(inside_total > 2000);
  CHECK(listed < 10 * inside_total);  // a pre-gate, not a list of everything (that would be ~28 x)

  // Non-finite points are never listed; a small box lists a small part of a large spread.
  std::vector<Eigen::Vector3d> pts(4000);
  for (auto& p : pts) p = Eigen::Vector3d(1e5 * u(rng), 2.0 * pi * u(rng) - pi, 1.5 * u(rng));
  pts[7] = Eigen::Vector3d(NAN, 0.0, 0.0);
  pts[8] = Eigen::Vector3d(5e4, INFINITY, 0.5);
  grid.build(pts, 3, Eigen::Vector3d(2e3, 0.1, 0.05));
  int candidates = 0;
  grid.for_each_candidate(Eigen::Vector3d(5e4, pi - 0.01, 0.7), Eigen::Vector3d(1e3, 0.05, 0.05), [&](int i) {
    CHECK(i != 7);
    CHECK(i != 8);
    ++candidates;
  });
  CHECK(candidates > 0);
  CHECK(candidates < 100);
  candidates = 0;
  grid.for_each_candidate(Eigen::Vector3d(5e4, 0.0, 0.7), Eigen::Vector3d(INFINITY, 4.0, INFINITY), [&](int) { ++candidates; });
  CHECK(candidates == 3998);
}

// A 2-D radar's polar scans use the same grid over (range, azimuth) only (a third value is a range
// rate): the pairs, NIS and order are the all-pairs test's.
TEST_CASE("polar scans: grid pre-gate = all pairs in order") {
  std::mt19937_64 rng(23);
  std::size_t total = 0;
  GatedPairs gated(0.999);
  for (int k = 0; k < 2000; ++k) {
    World w = spherical_world(rng);
    w.scan.sensor.frame = Frame::Polar;
    std::vector<std::tuple<int, int, double>> got;
    for (const GatedPair& p : gated.find(w.views, w.scan)) got.emplace_back(p.track, p.detection, p.nis);
    REQUIRE(got == all_pairs(w, 0.999));
    total += got.size();
  }
  CHECK(total > 10000);
}
