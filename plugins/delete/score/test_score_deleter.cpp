// Purpose: tests of delete.score: the drop below the peak by hand, a score-less track refused, and in tracker.multi a confirmed track deleted at the third miss (score_drop 5, P_D 0.9: 3 ln 10 = 6.9 >= 5 > 4.6) or, by covariance growth, at the first look its position standard deviation exceeds max_position_sd.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

std::unique_ptr<Deleter> deleter(const std::string& yaml) { return test::make_part<Deleter>("delete.score", yaml); }

struct SetCollector : Component {
  std::vector<std::vector<TrackEstimate>> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.emplace_back(s.tracks.begin(), s.tracks.end()); }
};

// One target at (10 t, 0, 0) m, sigma 2 m per axis, seen while `seen`; P_D 0.9 and the clutter
// density stated (the model of the score, no clutter drawn).
struct OneTarget {
  Rng rng{7};
  std::vector<Detection> detections;
  Scan scan_at(double t, bool seen) {
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
    s.detection_probability = 0.9;
    s.clutter_density = 1e-5;
    return s;
  }
};

std::shared_ptr<Component> tracker(const std::string& deleter_params) {
  return test::make("tracker.multi",
                    "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.gnn }, "
                    "initiator: { type: init.score, max_speed: 30 m/s }, deleter: { type: delete.score" +
                        deleter_params + " } }");
}

double position_sd(const TrackEstimate& t) {
  const Mat3 P = t.estimate.enu_covariance.topLeftCorner<3, 3>();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Mat3>(P).eigenvalues().maxCoeff());
}

}  // namespace

TEST_CASE("dropped when the score fell score_drop below its peak") {
  auto d = deleter("{ score_drop: 6.5 }");
  TrackView t;
  t.peak_score = 10.0;
  t.score = 10.0;
  CHECK_FALSE(d->drop(t));
  t.score = 3.6;
  CHECK_FALSE(d->drop(t));
  t.score = 3.5;
  CHECK(d->drop(t));
  t.score = std::nan("");
  CHECK_THROWS_WITH(d->drop(t), Catch::Contains("has no score"));
}

TEST_CASE("tracker.multi deletes at the third miss") {
  auto n = tracker(", score_drop: 5");
  SetCollector out;
  n->out.connect(&out.link, 1);
  test::start_run(*n);
  OneTarget sc;
  for (int k = 0; k < 12; ++k) n->on_scan(sc.scan_at(k, true), 0);
  REQUIRE(out.sets.back().size() == 1);
  const TrackEstimate last_hit = out.sets.back()[0];
  REQUIRE(last_hit.status == TrackStatus::Confirmed);
  // Two misses: 2 ln 10 = 4.6 below the peak (the last hit's score: hits raise it), coasting.
  for (int k = 12; k < 14; ++k) {
    n->on_scan(sc.scan_at(k, false), 0);
    REQUIRE(out.sets.back().size() == 1);
    CHECK(out.sets.back()[0].status == TrackStatus::Coasting);
    CHECK(out.sets.back()[0].score == Approx(last_hit.score + (k - 11) * std::log(0.1)).epsilon(1e-12));
  }
  n->on_scan(sc.scan_at(14, false), 0);
  REQUIRE(out.sets.back().size() == 1);
  CHECK(out.sets.back()[0].status == TrackStatus::Deleted);
  CHECK(out.sets.back()[0].score == Approx(last_hit.score + 3 * std::log(0.1)).epsilon(1e-12));
}

TEST_CASE("covariance growth deletes a coasting track") {
  const double bound = 15.0;
  auto n = tracker(", score_drop: 1000, max_position_sd: 15 m");
  SetCollector out;
  n->out.connect(&out.link, 1);
  test::start_run(*n);
  OneTarget sc;
  for (int k = 0; k < 12; ++k) n->on_scan(sc.scan_at(k, true), 0);
  REQUIRE(out.sets.back().size() == 1);
  REQUIRE(out.sets.back()[0].status == TrackStatus::Confirmed);
  CHECK(position_sd(out.sets.back()[0]) < 5.0);
  // Coasting: the position uncertainty grows each look; the track goes at the first look it
  // exceeds the bound, not before (score_drop 1000 never triggers here).
  int misses = 0;
  for (int k = 12; k < 200; ++k) {
    n->on_scan(sc.scan_at(k, false), 0);
    REQUIRE(out.sets.back().size() == 1);
    const TrackEstimate& t = out.sets.back()[0];
    ++misses;
    INFO("miss " << misses << ": sd " << position_sd(t) << " m");
    CHECK((t.status == TrackStatus::Deleted) == (position_sd(t) > bound));
    if (t.status == TrackStatus::Deleted) break;
  }
  CHECK(misses > 3);
  CHECK(misses < 100);
  CHECK(out.sets.back()[0].status == TrackStatus::Deleted);
}
