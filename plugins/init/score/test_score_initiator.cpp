// Purpose: tests of init.score and the track score it reads: the score increments by hand (a hit with known nu and S, a miss), Wald's thresholds, max_looks, the starts' score, a scan without P_D refused, and in tracker.multi a track confirmed at the first look whose score (recomputed from its published innovations) reaches the threshold.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

using namespace trackflow;

namespace {

std::unique_ptr<Initiator> initiator(const std::string& yaml) { return test::make_part<Initiator>("init.score", yaml); }

struct SetCollector : Component {
  std::vector<std::vector<TrackEstimate>> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.emplace_back(s.tracks.begin(), s.tracks.end()); }
};

// One target at (10 t, 0, 0) m, measured with sigma 2 m per axis; the scan states P_D and the
// clutter density (no clutter is drawn: the density is the model the score uses).
struct OneTarget {
  Rng rng{3};
  std::vector<Detection> detections;
  Scan scan_at(double t, bool seen, double pd = 0.9, double density = 1e-5) {
    detections.clear();
    if (seen) {
      Detection d;
      d.value = Vec3(10.0 * t, 0.0, 0.0) + 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = 1;
      detections.push_back(d);
    }
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = detections;
    s.detection_probability = pd;
    s.clutter_density = density;
    return s;
  }
};

// ln(P_D N(nu; 0, S) / beta) straight from the Gaussian density, not through track_score.
double hit_by_hand(double pd, double density, const Eigen::VectorXd& nu, const Eigen::MatrixXd& S) {
  const double n = static_cast<double>(nu.size());
  const double g = std::exp(-0.5 * nu.dot(S.inverse() * nu)) / std::sqrt(std::pow(2.0 * std::numbers::pi, n) * S.determinant());
  return std::log(pd * g / density);
}

}  // namespace

TEST_CASE("score increments by hand: a hit, a miss") {
  // nu = (2, 3, 1), S = diag(4, 9, 1): d^2 = 3, |S| = 36.
  Eigen::VectorXd nu(3);
  nu << 2.0, 3.0, 1.0;
  const Eigen::MatrixXd S = Eigen::Vector3d(4.0, 9.0, 1.0).asDiagonal();
  const double expected = std::log(0.9) + std::log(1e6) - 0.5 * (3.0 * std::log(2.0 * std::numbers::pi) + std::log(36.0) + 3.0);
  CHECK(track_score::hit(0.9, 1e-6, 3.0, std::log(36.0), 3) == Approx(expected).epsilon(1e-14));
  CHECK(track_score::hit(0.9, 1e-6, 3.0, std::log(36.0), 3) == Approx(hit_by_hand(0.9, 1e-6, nu, S)).epsilon(1e-12));
  CHECK(expected == Approx(7.6616).margin(1e-4));  // 13.7102 - (5.5136 + 3.5835 + 3) / 2
  CHECK(track_score::miss(0.9) == Approx(std::log(0.1)).epsilon(1e-14));
  CHECK(track_score::miss(0.9, 0.99) == Approx(std::log(1.0 - 0.891)).epsilon(1e-14));
}

TEST_CASE("Wald thresholds confirm and fail, max_looks fails") {
  // alpha = 1e-3, beta = 0.1: T_c = ln(0.9 / 1e-3) = 6.8024, T_d = ln(0.1 / 0.999) = -2.3016.
  auto init = initiator("{ max_speed: 10 m/s, false_track_probability: 1e-3, true_track_loss_probability: 0.1, max_looks: 6 }");
  TrackView t;
  t.looks = 3;
  t.score = 6.80;
  CHECK_FALSE(init->confirmed(t));
  CHECK_FALSE(init->failed(t));
  t.score = 6.81;
  CHECK(init->confirmed(t));
  CHECK_FALSE(init->failed(t));
  t.score = -2.30;
  CHECK_FALSE(init->failed(t));
  t.score = -2.31;
  CHECK(init->failed(t));
  t.score = 1.0;
  t.looks = 5;
  CHECK_FALSE(init->failed(t));
  t.looks = 6;  // undecided after max_looks
  CHECK(init->failed(t));
  t.score = 7.0;
  CHECK(init->confirmed(t));
  CHECK_FALSE(init->failed(t));
  t.score = std::nan("");
  CHECK_THROWS_AS(init->confirmed(t), DataError);
  // The defaults: alpha = 1e-6, beta = 0.1, T_c = ln(0.9e6) = 13.71.
  auto plain = initiator("{ max_speed: 10 m/s }");
  t.looks = 3;
  t.score = 13.70;
  CHECK_FALSE(plain->confirmed(t));
  t.score = 13.72;
  CHECK(plain->confirmed(t));
  CHECK_THROWS_WITH(initiator("{ max_speed: 1 m/s, false_track_probability: 0.5, true_track_loss_probability: 0.5 }"),
                    Catch::Contains("must be below 1"));
}

TEST_CASE("starts carry start_score, a scan without P_D refused") {
  auto init = initiator("{ max_speed: 20 m/s, start_score: 2.5 }");
  OneTarget sc;
  std::vector<TrackStart> starts;
  const std::vector<int> first{0};
  Scan s0 = sc.scan_at(0.0, true);
  init->initiate(s0, first, starts);
  CHECK(starts.empty());
  Scan s1 = sc.scan_at(1.0, true);
  init->initiate(s1, first, starts);
  REQUIRE(starts.size() == 1);
  CHECK(starts[0].score == 2.5);
  CHECK(starts[0].second == 0);
  Scan silent = sc.scan_at(2.0, true, std::nan(""));
  CHECK_THROWS_WITH(init->initiate(silent, first, starts), Catch::Contains("states no detection probability"));
  Scan no_density = sc.scan_at(2.0, true, 0.9, std::nan(""));
  CHECK_THROWS_AS(init->initiate(no_density, first, starts), DataError);
}

// The track score recomputed from the estimator's own published innovation and S each look
// (independent of the tracker's gate), and the confirmation at the first look it reaches T_c.
TEST_CASE("tracker.multi confirms when the score reaches T_c") {
  auto n = test::make("tracker.multi",
                      "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.gnn }, "
                      "initiator: { type: init.score, max_speed: 30 m/s }, deleter: { type: delete.score } }");
  SetCollector out;
  n->out.connect(&out.link, 1);
  test::start_run(*n);
  OneTarget sc;
  const double Tc = std::log(0.9 / 1e-6);
  double L = 0.0;
  int confirmed_at_hits = 0;
  for (int k = 0; k < 12; ++k) {
    n->on_scan(sc.scan_at(k, k != 3), 0);  // one miss while tentative, at t = 3 s
    REQUIRE(out.sets.back().size() == (k == 0 ? 0u : 1u));
    if (k == 0) continue;
    const TrackEstimate& t = out.sets.back()[0];
    if (k >= 2) {
      if (t.estimate.updated) {
        const Eigen::VectorXd nu = t.estimate.innovation;
        const Eigen::MatrixXd S = t.estimate.innovation_covariance;
        L += hit_by_hand(0.9, 1e-5, nu, S);
      } else {
        L += std::log(0.1);
      }
    }
    INFO("t = " << k << " s, score " << t.score);
    CHECK(t.score == Approx(L).epsilon(1e-9).margin(1e-9));
    const bool was_confirmed = confirmed_at_hits > 0;
    if (t.status == TrackStatus::Confirmed && !was_confirmed) confirmed_at_hits = t.hits;
    // Tentative exactly while the score has been below T_c.
    CHECK((t.status == TrackStatus::Tentative) == (!was_confirmed && L < Tc));
  }
  // Each hit adds about 3 here (ln(0.9/1e-5) = 11.4 less ln|2 pi S|/2 + d^2/2), one miss takes 2.3: the
  // two initiating detections, then several hits.
  CHECK(confirmed_at_hits >= 5);
  CHECK(confirmed_at_hits <= 9);
}
