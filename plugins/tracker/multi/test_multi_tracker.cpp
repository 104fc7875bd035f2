// Purpose: tests of tracker.multi with filter.kalman, assoc.gnn / assoc.nearest, init.m_of_n and delete.misses, scans fed by hand: two targets in clutter become two confirmed tracks that keep their targets; ids are never reused; a track is deleted after its misses; a scan that was not a look changes nothing; each track's score gains the hit or miss increment per look; the run result survives the codec; per-track adapters (adapt.innovation_r) adapt each track's own R, restart with a new track, and are refused when the estimator cannot serve them.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

struct SetCollector : Component {
  struct Seen {
    double time;
    std::vector<TrackEstimate> tracks;
  };
  std::vector<Seen> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.push_back({s.time, {s.tracks.begin(), s.tracks.end()}}); }
  void attach_to(Component& c) { c.out.connect(&link, 1); }
};

std::string tracker_yaml(const std::string& associator, int max_misses = 3) {
  return "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: " + associator +
         " }, initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 50 m/s }, deleter: { type: delete.misses, "
         "max_misses: " +
         std::to_string(max_misses) + " } }";
}

// Two targets 200 m apart in x at 10 m/s, crossing in y: target 1 (0, -100) -> +y, target 2 (200, 100) -> -y...
// measured every second with sigma 2 m, P_D 1, and `clutter` false detections uniform in a 1 km cube.
struct Scenario {
  Rng rng{5};
  std::vector<Detection> detections;
  Scan scan_at(double t, int clutter, bool see_second = true) {
    detections.clear();
    const Vec3 p1(0.0, -100.0 + 10.0 * t, 0.0), p2(200.0, 100.0 - 10.0 * t, 0.0);
    add(p1, 1);
    if (see_second) add(p2, 2);
    for (int k = 0; k < clutter; ++k) {
      Detection d;
      d.value = Vec3(1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500);
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = kOriginClutter;
      detections.push_back(d);
    }
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = detections;
    s.detection_probability = 0.99;
    s.clutter_density = (clutter > 0 ? clutter : 1) / 1e9;
    return s;
  }
  void add(const Vec3& p, std::uint32_t origin) {
    Detection d;
    d.value = p + 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
    d.covariance = MeasCov::Identity(3, 3) * 4.0;
    d.origin = origin;
    detections.push_back(d);
  }
};

std::vector<const TrackEstimate*> confirmed(const SetCollector::Seen& s) {
  std::vector<const TrackEstimate*> out;
  for (const TrackEstimate& t : s.tracks)
    if (t.status == TrackStatus::Confirmed || t.status == TrackStatus::Coasting) out.push_back(&t);
  return out;
}

}  // namespace

TEST_CASE("two targets in clutter: two tracks that keep them") {
  for (const char* assoc : {"assoc.gnn", "assoc.nearest"}) {
    INFO(assoc);
    auto n = test::make("tracker.multi", tracker_yaml(assoc));
    SetCollector out;
    out.attach_to(*n);
    test::start_run(*n);
    Scenario sc;
    for (int k = 0; k < 20; ++k) n->on_scan(sc.scan_at(k, 5), 0);
    REQUIRE(out.sets.size() == 20);
    // From the 4th scan on (two to start, two more to confirm 3 of 4) both targets are confirmed.
    std::map<std::uint64_t, std::uint32_t> target_of;
    for (size_t k = 4; k < out.sets.size(); ++k) {
      const auto c = confirmed(out.sets[k]);
      REQUIRE(c.size() == 2);
      for (const TrackEstimate* t : c) {
        const double time = out.sets[k].time;
        const Vec3 p1(0.0, -100.0 + 10.0 * time, 0.0), p2(200.0, 100.0 - 10.0 * time, 0.0);
        const Vec3 at = t->estimate.enu.head<3>();
        const std::uint32_t nearest = (at - p1).norm() < (at - p2).norm() ? 1 : 2;
        CHECK((at - (nearest == 1 ? p1 : p2)).norm() < 10.0);
        // A track follows one target all along (no swap, no break).
        if (!target_of.count(t->id)) target_of[t->id] = nearest;
        CHECK(target_of[t->id] == nearest);
        CHECK(t->estimate.target == nearest);  // the origin of its initiating detections
      }
    }
    CHECK(target_of.size() == 2);
  }
}

TEST_CASE("misses delete, ids never reused, non-looks ignored") {
  auto n = test::make("tracker.multi", tracker_yaml("assoc.gnn", 2));
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  for (int k = 0; k < 8; ++k) n->on_scan(sc.scan_at(k, 0), 0);
  REQUIRE(confirmed(out.sets.back()).size() == 2);
  std::set<std::uint64_t> ids;
  for (const TrackEstimate* t : confirmed(out.sets.back())) ids.insert(t->id);
  // A scan with valid: false: the same tracks, no miss counted.
  Scan off = sc.scan_at(8, 0);
  off.valid = false;
  n->on_scan(off, 0);
  for (const TrackEstimate& t : out.sets.back().tracks) CHECK(t.misses == 0);
  // The second target unseen for two looks: coasting, then deleted (published once as deleted).
  n->on_scan(sc.scan_at(9, 0, false), 0);
  int coasting = 0;
  for (const TrackEstimate& t : out.sets.back().tracks) coasting += t.status == TrackStatus::Coasting;
  CHECK(coasting == 1);
  n->on_scan(sc.scan_at(10, 0, false), 0);
  int deleted = 0;
  for (const TrackEstimate& t : out.sets.back().tracks) deleted += t.status == TrackStatus::Deleted;
  CHECK(deleted == 1);
  n->on_scan(sc.scan_at(11, 0, false), 0);
  CHECK(out.sets.back().tracks.size() == 1);
  // It comes back: a new track with a new id.
  for (int k = 12; k < 18; ++k) n->on_scan(sc.scan_at(k, 0), 0);
  const auto c = confirmed(out.sets.back());
  REQUIRE(c.size() == 2);
  int fresh = 0;
  for (const TrackEstimate* t : c) fresh += !ids.count(t->id);
  CHECK(fresh == 1);
}

TEST_CASE("run result codec, wrong part refused") {
  auto n = test::make("tracker.multi", tracker_yaml("assoc.gnn"));
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  for (int k = 0; k < 6; ++k) n->on_scan(sc.scan_at(k, 3), 0);
  std::unique_ptr<RunResult> r = n->end_run();
  auto* codec = dynamic_cast<RunResultCodec*>(n.get());
  REQUIRE(codec);
  std::string bytes;
  ByteWriter w(bytes);
  codec->save_run_result(*r, w);
  ByteReader rd(bytes.data(), bytes.size());
  std::unique_ptr<RunResult> back = codec->load_run_result(rd);
  CHECK(rd.done());
  n->merge(*back);
  Summary s;
  n->finish(s, FinishContext{});
  REQUIRE(s.find("tracks_confirmed_per_run"));
  CHECK(s.find("tracks_confirmed_per_run")->value == 2.0);
  CHECK(s.find("scans")->value == 6.0);
  // A wrong part type in a slot is refused at creation, naming what was wanted.
  CHECK_THROWS_WITH(test::make("tracker.multi",
                               "{ estimator: { type: filter.kalman }, associator: { type: init.m_of_n, max_speed: 1 m/s }, "
                               "initiator: { type: init.m_of_n, max_speed: 1 m/s }, deleter: { type: delete.misses } }"),
                    Catch::Contains("init.m_of_n"));
}

// A coasting track shows no innovation of an earlier scan, and a track in a reused slot (this
// run's or an earlier run's) starts with nothing of the slot's previous track: otherwise the
// published sets would depend on which runs a worker thread ran before.
TEST_CASE("coasting tracks and reused slots carry nothing stale") {
  auto n = test::make("tracker.multi", tracker_yaml("assoc.gnn", 2));
  SetCollector out;
  out.attach_to(*n);
  auto run_once = [&](std::uint64_t run) {
    out.sets.clear();
    test::start_run(*n, run);
    Scenario sc;
    for (int k = 0; k < 8; ++k) n->on_scan(sc.scan_at(k, 0, k < 6), 0);  // target 2 unseen from t = 6 s
    n->end_run();
    return out.sets;
  };
  const auto first = run_once(0);
  // Target 2's track at t = 6 s: coasting, not updated, no innovation.
  bool saw_coasting = false;
  for (const TrackEstimate& t : first[6].tracks)
    if (t.status == TrackStatus::Coasting) {
      saw_coasting = true;
      CHECK_FALSE(t.estimate.updated);
      CHECK(t.estimate.innovation.size() == 0);
    }
  CHECK(saw_coasting);
  // The same run again on the same node (its slots now spares from the first): the same sets.
  const auto again = run_once(0);
  REQUIRE(again.size() == first.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    REQUIRE(again[k].tracks.size() == first[k].tracks.size());
    for (std::size_t i = 0; i < first[k].tracks.size(); ++i) {
      const TrackEstimate &a = first[k].tracks[i], &b = again[k].tracks[i];
      CHECK(a.id == b.id);
      CHECK(a.status == b.status);
      CHECK(a.estimate.updated == b.estimate.updated);
      CHECK(a.estimate.nis == b.estimate.nis);
      CHECK(a.estimate.enu == b.estimate.enu);
      CHECK(a.estimate.innovation.size() == b.estimate.innovation.size());
    }
  }
}

// The track score (tracker.hpp, track_score) per look: a detection used adds ln(P_D / beta) +
// ln N(nu; 0, S), recomputed here from the estimator's published innovation and S; a miss adds
// ln(1 - P_D); a scan that states no P_D makes it NaN.
TEST_CASE("the track score: a hit or miss increment per look") {
  auto n = test::make("tracker.multi", tracker_yaml("assoc.gnn", 3));
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  std::map<std::uint64_t, double> previous;
  int hits = 0, misses = 0;
  for (int k = 0; k < 10; ++k) {
    n->on_scan(sc.scan_at(k, 0, k != 5 && k != 6), 0);  // target 2 unseen at t = 5, 6 s
    const double pd = 0.99, beta = 1e-9;
    for (const TrackEstimate& t : out.sets.back().tracks) {
      if (!previous.count(t.id)) {
        CHECK(t.score == 0.0);  // init.m_of_n's starts: the two initiating detections are the reference
      } else if (t.estimate.updated) {
        const Eigen::VectorXd nu = t.estimate.innovation;
        const Eigen::MatrixXd S = t.estimate.innovation_covariance;
        const double dL = std::log(pd / beta) - 0.5 * (nu.dot(S.inverse() * nu) + std::log(S.determinant()) +
                                                       3.0 * std::log(2.0 * std::acos(-1.0)));
        CHECK(t.score - previous[t.id] == Approx(dL).epsilon(1e-9));
        ++hits;
      } else {
        CHECK(t.score - previous[t.id] == Approx(std::log(0.01)).epsilon(1e-12));
        ++misses;
      }
      previous[t.id] = t.score;
    }
  }
  CHECK(hits >= 10);
  CHECK(misses == 2);
  // A scan without P_D: no score from then on (init.m_of_n and delete.misses do not need one).
  Scan silent = sc.scan_at(10, 0);
  silent.detection_probability = std::numeric_limits<double>::quiet_NaN();
  n->on_scan(silent, 0);
  n->on_scan(sc.scan_at(11, 0), 0);
  REQUIRE(confirmed(out.sets.back()).size() == 2);
  for (const TrackEstimate* t : confirmed(out.sets.back())) CHECK(std::isnan(t->score));
}

namespace {

// Per-track adapters: two targets 400 m apart in x, both reported with sigma 2 m (R = 4 m2 I),
// target 1 measured with that noise, target 2 with sigma `noisy_sigma` (a sensor that claims too
// little noise for it); target 2 unseen while `hide_second` says so.
struct NoisyPair {
  Rng rng{11};
  std::vector<Detection> detections;
  double noisy_sigma = 8.0;
  Scan scan_at(double t, bool see_second = true, double second_sigma = -1.0) {
    detections.clear();
    add(Vec3(0.0, -100.0 + 10.0 * t, 0.0), 1, 2.0);
    if (see_second) add(Vec3(400.0, 100.0 - 10.0 * t, 0.0), 2, second_sigma > 0.0 ? second_sigma : noisy_sigma);
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = detections;
    s.detection_probability = 0.99;
    s.clutter_density = 1e-9;
    return s;
  }
  void add(const Vec3& p, std::uint32_t origin, double sigma) {
    Detection d;
    d.value = p + sigma * Vec3(rng.normal(), rng.normal(), rng.normal());
    d.covariance = MeasCov::Identity(3, 3) * 4.0;
    d.origin = origin;
    detections.push_back(d);
  }
};

const char* const kAdaptedTracker =
    "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 },\n"
    "  adapters: [ { type: adapt.innovation_r, window: 10, warmup: 5 } ],\n"
    "  associator: { type: assoc.gnn, gate_probability: 0.999999 },\n"
    "  initiator: { type: init.m_of_n, m: 2, n: 3, max_speed: 100 m/s },\n"
    "  deleter: { type: delete.misses, max_misses: 3 } }";

// The adapted sigma_x annotation of the track following `target` in set `s`; NaN when none.
double adapted_sigma(const SetCollector::Seen& s, std::uint32_t target, std::uint64_t* id = nullptr) {
  for (const TrackEstimate& t : s.tracks)
    if (t.status != TrackStatus::Deleted && t.estimate.target == target && t.estimate.annotation_count == 3) {
      if (id) *id = t.id;
      return t.estimate.annotations[0];
    }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

// adapt.innovation_r per track: the noisy target's track learns its larger R, the other keeps
// the nominal 2 m; after the noisy track is deleted, a new track in its slot starts from the
// measurements' own R again, nothing of the slot's previous adapter state.
TEST_CASE("per-track adapters: each track adapts its own R") {
  auto n = test::make("tracker.multi", kAdaptedTracker);
  SetCollector out;
  out.attach_to(*n);
  auto run_once = [&](std::uint64_t run) {
    out.sets.clear();
    test::start_run(*n, run);
    NoisyPair sc;
    for (int k = 0; k < 60; ++k) n->on_scan(sc.scan_at(k), 0);             // both, target 2 noisy
    for (int k = 60; k < 66; ++k) n->on_scan(sc.scan_at(k, false), 0);     // target 2 gone: deleted
    for (int k = 66; k < 70; ++k) n->on_scan(sc.scan_at(k, true, 2.0), 0);  // back, as noisy as claimed
    n->end_run();
    return out.sets;
  };
  const auto sets = run_once(0);
  REQUIRE(sets.size() == 70);
  std::uint64_t quiet_id = 0, noisy_id = 0;
  const double quiet = adapted_sigma(sets[59], 1, &quiet_id), noisy = adapted_sigma(sets[59], 2, &noisy_id);
  INFO("adapted sigma_x at t = 59 s: target 1 " << quiet << " m, target 2 " << noisy << " m");
  CHECK(quiet == Approx(2.0).margin(0.8));
  CHECK(noisy == Approx(8.0).margin(3.0));
  CHECK(noisy_id != quiet_id);
  // One track per target all along the first phase (the noisy one was not lost and restarted).
  for (int k = 10; k < 60; ++k) {
    std::uint64_t id1 = 0, id2 = 0;
    adapted_sigma(sets[static_cast<size_t>(k)], 1, &id1);
    adapted_sigma(sets[static_cast<size_t>(k)], 2, &id2);
    CHECK(id1 == quiet_id);
    CHECK(id2 == noisy_id);
  }
  // The noisy track deleted while its target is gone; the target's new track (started from the
  // detections at t = 66, 67 s, in the noisy one's slot, the only spare) has a new id and at its
  // start the measurements' own sigma, 2 m exactly, then stays near it.
  std::uint64_t gone_id = 0;
  CHECK(std::isnan(adapted_sigma(sets[65], 2, &gone_id)));
  std::uint64_t fresh_id = 0;
  const double fresh = adapted_sigma(sets[67], 2, &fresh_id);
  CHECK(fresh_id != noisy_id);
  CHECK(fresh_id != 0);
  CHECK(fresh == Approx(2.0).epsilon(1e-12));
  CHECK(adapted_sigma(sets[69], 2) == Approx(2.0).margin(1.0));
  CHECK(adapted_sigma(sets[69], 1) == Approx(quiet).margin(0.5));
  // Deterministic: the same run again on the same node (its slots reused) gives the same values.
  const auto again = run_once(0);
  REQUIRE(again.size() == sets.size());
  for (size_t k = 0; k < sets.size(); ++k) {
    REQUIRE(again[k].tracks.size() == sets[k].tracks.size());
    for (size_t i = 0; i < sets[k].tracks.size(); ++i) {
      const Estimate &a = sets[k].tracks[i].estimate, &b = again[k].tracks[i].estimate;
      CHECK(a.enu == b.enu);
      REQUIRE(a.annotation_count == b.annotation_count);
      for (int j = 0; j < a.annotation_count; ++j)
        CHECK((a.annotations[j] == b.annotations[j] || (std::isnan(a.annotations[j]) && std::isnan(b.annotations[j]))));
    }
  }
}

// What the estimator cannot offer is refused when the tracker is made, at the entry's line:
// adapt.range_r writes a spherical R, filter.kalman's is Cartesian.
TEST_CASE("per-track adapters the estimator cannot serve") {
  const std::string yaml =
      "{ estimator: { type: filter.kalman },\n"
      "  adapters: [ { type: adapt.innovation_r },\n"
      "              { type: adapt.range_r, alpha: 400 urad2, beta: 900 urad2, reference_range: 10 km } ],\n"
      "  associator: { type: assoc.gnn }, initiator: { type: init.m_of_n, max_speed: 1 m/s },\n"
      "  deleter: { type: delete.misses } }";
  try {
    test::make("tracker.multi", yaml);
    FAIL("adapt.range_r on a filter.kalman estimator was accepted");
  } catch (const ConfigError& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find("adapt.range_r") != std::string::npos);
    CHECK(std::string(e.what()).find("spherical") != std::string::npos);
    CHECK(e.where().line == 3);
  }
  // Only adapters may be given there.
  CHECK_THROWS_WITH(test::make("tracker.multi",
                               "{ estimator: { type: filter.kalman }, adapters: [ { type: filter.kalman } ], "
                               "associator: { type: assoc.gnn }, initiator: { type: init.m_of_n, max_speed: 1 m/s }, "
                               "deleter: { type: delete.misses } }"),
                    Catch::Contains("filter.kalman"));
}

// init.m_of_n start: one_point — a detection no track took starts a tentative track at once, at rest
// with the velocity prior: both targets are tentative after the first scan (one hit each, zero
// velocity, velocity variance max_speed^2 / 4), confirmed at the third scan with 3 hits of 3 looks
// (a scan earlier than two-point), and followed to the end.
TEST_CASE("one-point starts: tentative at once and confirmed") {
  auto n = test::make("tracker.multi",
                      "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.gnn }, initiator: "
                      "{ type: init.m_of_n, m: 3, n: 4, max_speed: 50 m/s, start: one_point }, deleter: { type: "
                      "delete.misses, max_misses: 3 } }");
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  for (int k = 0; k < 12; ++k) n->on_scan(sc.scan_at(k, 0), 0);
  REQUIRE(out.sets.size() == 12);
  REQUIRE(out.sets[0].tracks.size() == 2);
  for (const TrackEstimate& t : out.sets[0].tracks) {
    CHECK(t.status == TrackStatus::Tentative);
    CHECK(t.hits == 1);
    CHECK(t.estimate.enu.tail<3>().isZero());
    CHECK(t.estimate.enu_covariance(3, 3) == Approx(25.0 * 25.0));
    CHECK(t.estimate.enu_covariance(0, 3) == 0.0);  // no position-velocity cross term
  }
  CHECK(confirmed(out.sets[1]).empty());
  REQUIRE(confirmed(out.sets[2]).size() == 2);
  for (size_t k = 2; k < out.sets.size(); ++k) {
    REQUIRE(confirmed(out.sets[k]).size() == 2);
    for (const TrackEstimate* t : confirmed(out.sets[k])) CHECK((t->estimate.target == 1 || t->estimate.target == 2));
  }
  // The velocity is learnt: 10 m/s along y at the end, within a few sigma.
  for (const TrackEstimate* t : confirmed(out.sets.back())) CHECK(std::fabs(std::fabs(t->estimate.enu(4)) - 10.0) < 1.5);
}

// One-point starts need an estimator that offers them: filter.imm is refused at its type line;
// a velocity_sigma with two-point starts is refused at its own line.
TEST_CASE("one-point starts refused where they cannot be") {
  try {
    (void)test::make("tracker.multi",
                     "{ estimator: { type: filter.imm, modes: [{ motion: constant_velocity }, { motion: "
                     "constant_acceleration }], transition: [0.9, 0.1, 0.1, 0.9] }, associator: { type: assoc.gnn }, "
                     "initiator: { type: init.m_of_n, max_speed: 50 m/s, start: one_point }, deleter: { type: "
                     "delete.misses } }");
    FAIL("filter.imm with one-point starts was accepted");
  } catch (const ConfigError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("starts tracks from one point, which filter.imm cannot"));
  }
  CHECK_THROWS_WITH(test::make_part<Initiator>("init.m_of_n", "{ max_speed: 50 m/s, velocity_sigma: 10 m/s }"),
                    Catch::Contains("velocity_sigma") && Catch::Contains("one_point"));
}
