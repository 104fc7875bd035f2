// Purpose: tests of init.m_of_n: its pairing is the optimum of the dense pairing problem (every previous detection against every current one) on random scans; the gate by hand; M-of-N confirmation and failure.
#include <catch2/catch.hpp>

#include "assignment/linear_assignment.hpp"
#include "plugin_fixture.hpp"

#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <vector>

using namespace trackflow;

namespace {

std::unique_ptr<Initiator> initiator(const std::string& yaml) { return test::make_part<Initiator>("init.m_of_n", yaml); }

struct OwnedScan {
  std::vector<Detection> detections;
  Scan scan;
};

OwnedScan cartesian_scan(double time, const std::vector<Vec3>& positions, double sigma) {
  OwnedScan s;
  for (const Vec3& p : positions) {
    Detection d;
    d.value = p;
    d.covariance = MeasCov::Identity(3, 3) * sigma * sigma;
    s.detections.push_back(d);
  }
  s.scan.time = time;
  s.scan.sensor.frame = Frame::Cartesian;
  s.scan.detections = s.detections;
  return s;
}

std::vector<int> all(const OwnedScan& s) {
  std::vector<int> v(s.detections.size());
  std::iota(v.begin(), v.end(), 0);
  return v;
}

// The pairing problem solved densely, as the plugin did before its grid and clusters: rows =
// previous detections, columns = current ones plus one "no pair" column per row (cost 1).
double dense_optimum(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double T, double vmax, double k,
                     double sigma) {
  const int rows = static_cast<int>(a.size()), m = static_cast<int>(b.size()), cols = m + rows;
  std::vector<double> c(static_cast<std::size_t>(rows * cols), std::numeric_limits<double>::infinity());
  const double s = std::sqrt(3.0) * sigma;  // root of the trace of sigma^2 I
  const double gate = vmax * T + k * std::hypot(s, s);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < m; ++j) {
      const double d = (b[static_cast<std::size_t>(j)] - a[static_cast<std::size_t>(i)]).norm();
      if (d <= gate) c[static_cast<std::size_t>(i * cols + j)] = d / gate;
    }
    c[static_cast<std::size_t>(i * cols + m + i)] = 1.0;
  }
  assignment::LinearAssignment solver;
  return rows == 0 ? 0.0 : solver.solve(std::span<const double>(c), rows, cols).total_cost;
}

}  // namespace

TEST_CASE("pairs = dense pairing optimum on 2000 random scan pairs") {
  Rng rng(12);
  auto init = initiator("{ m: 3, n: 4, max_speed: 10 m/s, gate_sigmas: 3 }");
  int with_starts = 0;
  for (int k = 0; k < 2000; ++k) {
    const double sigma = 0.5 + 2.0 * rng.uniform(), T = 1.0 + 4.0 * rng.uniform();
    const double extent = k % 4 == 0 ? 20.0 : 300.0 * rng.uniform() + 1.0;
    std::vector<Vec3> a(static_cast<std::size_t>(rng.uniform() * 25)), b(static_cast<std::size_t>(rng.uniform() * 25));
    for (Vec3& p : a) p = Vec3(extent * rng.uniform(), extent * rng.uniform(), 10.0 * rng.uniform());
    for (Vec3& p : b) p = Vec3(extent * rng.uniform(), extent * rng.uniform(), 10.0 * rng.uniform());
    init->reset();
    const OwnedScan first = cartesian_scan(0.0, a, sigma), second = cartesian_scan(T, b, sigma);
    std::vector<TrackStart> starts;
    init->initiate(first.scan, all(first), starts);
    REQUIRE(starts.empty());  // nothing to pair with yet
    init->initiate(second.scan, all(second), starts);
    // The plugin's pairs: distinct on both sides, inside the gate; their cost as the dense problem counts it.
    const double s = std::sqrt(3.0) * sigma, gate = 10.0 * T + 3.0 * std::hypot(s, s);
    std::vector<int> used_b(b.size(), 0);
    double cost = static_cast<double>(a.size() - starts.size());
    for (const TrackStart& st : starts) {
      REQUIRE(st.second >= 0);
      REQUIRE(st.second < static_cast<int>(b.size()));
      REQUIRE(used_b[static_cast<std::size_t>(st.second)]++ == 0);
      const double d = (b[static_cast<std::size_t>(st.second)] - st.first.value.head<3>()).norm();
      REQUIRE(d <= gate);
      cost += d / gate;
    }
    CHECK(cost == Approx(dense_optimum(a, b, T, 10.0, 3.0, sigma)).margin(1e-12));
    with_starts += starts.empty() ? 0 : 1;
  }
  CHECK(with_starts > 1000);
}

TEST_CASE("the gate by hand, an unpaired detection waits one scan") {
  auto init = initiator("{ max_speed: 10 m/s, gate_sigmas: 2 }");
  // sigma = 1 m per axis: s = sqrt(3) per detection, margin 2 sqrt(6) = 4.899 m; T = 1 s: gate 14.899 m.
  std::vector<TrackStart> starts;
  const OwnedScan s0 = cartesian_scan(0.0, {Vec3(0, 0, 0)}, 1.0);
  const OwnedScan inside = cartesian_scan(1.0, {Vec3(14.89, 0, 0)}, 1.0);
  const OwnedScan outside = cartesian_scan(1.0, {Vec3(14.91, 0, 0)}, 1.0);
  init->initiate(s0.scan, all(s0), starts);
  init->initiate(inside.scan, all(inside), starts);
  CHECK(starts.size() == 1);
  init->reset();
  starts.clear();
  init->initiate(s0.scan, all(s0), starts);
  init->initiate(outside.scan, all(outside), starts);
  CHECK(starts.empty());
  // The detection at t = 0 has waited its one scan: (-5, 0, 0) at t = 2 s would pair with it (5 m in
  // 2 s) but not with the one at t = 1 s (19.91 m > 14.899 m).
  const OwnedScan later = cartesian_scan(2.0, {Vec3(-5, 0, 0), Vec3(20, 0, 0)}, 1.0);
  init->initiate(later.scan, all(later), starts);
  REQUIRE(starts.size() == 1);  // (20, 0, 0) pairs with the t = 1 s detection (5.09 m)
  CHECK(starts[0].first.time == 1.0);
  CHECK(starts[0].second == 1);
}

TEST_CASE("M of N: confirmed with m hits in n looks, else failed") {
  auto init = initiator("{ m: 3, n: 4, max_speed: 10 m/s }");
  TrackView t;
  t.looks = 3;
  t.history = 0b111;
  CHECK(init->confirmed(t));
  t.history = 0b011;
  CHECK_FALSE(init->confirmed(t));
  CHECK_FALSE(init->failed(t));
  t.looks = 4;
  t.history = 0b1011;
  CHECK(init->confirmed(t));
  t.history = 0b0011;
  CHECK(init->failed(t));
}
