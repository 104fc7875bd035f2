// Purpose: tests of tracker.tomht: two targets in clutter give two confirmed tracks that keep their targets; a crossing the GNN tracker swaps and the MHT does not; one hypothesis reproduces tracker.multi with assoc.gnn; the ranked hypotheses equal brute-force enumeration of compatible leaf sets; RankedSums against brute force; determinism; run result codec and summary.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"
#include "ranked_sums.hpp"
#include "tomht_engine.hpp"

#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
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

std::string tomht_yaml(const std::string& extra = "") {
  return "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, max_speed: 50 m/s" + (extra.empty() ? "" : ", " + extra) +
         " }";
}

// Two targets 200 m apart in x at 10 m/s, crossing in y (as test_multi_tracker.cpp): sigma 2 m,
// P_D 1, `clutter` false detections uniform in a 1 km cube.
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
    return make_scan(t, clutter);
  }
  void add(const Vec3& p, std::uint32_t origin, double sigma = 2.0) {
    Detection d;
    d.value = p + sigma * Vec3(rng.normal(), rng.normal(), rng.normal());
    d.covariance = MeasCov::Identity(3, 3) * sigma * sigma;
    d.origin = origin;
    detections.push_back(d);
  }
  Scan make_scan(double t, int clutter) const {
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = detections;
    s.detection_probability = 0.99;
    s.clutter_density = (clutter > 0 ? clutter : 1) / 1e9;
    return s;
  }
};

std::vector<const TrackEstimate*> confirmed(const SetCollector::Seen& s) {
  std::vector<const TrackEstimate*> out;
  for (const TrackEstimate& t : s.tracks)
    if (t.status == TrackStatus::Confirmed || t.status == TrackStatus::Coasting) out.push_back(&t);
  return out;
}

}  // namespace

TEST_CASE("two targets in clutter give two tracks that keep them") {
  auto n = test::make("tracker.tomht", tomht_yaml());
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  for (int k = 0; k < 20; ++k) n->on_scan(sc.scan_at(k, 5), 0);
  REQUIRE(out.sets.size() == 20);
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
      if (!target_of.count(t->id)) target_of[t->id] = nearest;
      CHECK(target_of[t->id] == nearest);
      CHECK(t->estimate.target == nearest);
      CHECK(t->score >= std::log(0.9 / 1e-6));  // confirmed at Wald's upper threshold
    }
  }
  CHECK(target_of.size() == 2);
  // Track ids are unique in every set.
  for (const auto& s : out.sets) {
    std::set<std::uint64_t> ids;
    for (const TrackEstimate& t : s.tracks) CHECK(ids.insert(t.id).second);
  }
}

namespace {

// Two targets crossing in the plane at t = 10 s at a shallow angle: A from (-100, -s) with
// velocity (10, s/10), B from (-100, s) with velocity (10, -s/10); detections every second with
// sigma `sigma`; at t in `missed` only one detection (the targets' mean: a merged return).
struct Crossing {
  Rng rng;
  double spread, sigma;
  std::set<int> merged;
  std::vector<Detection> detections;
  Crossing(std::uint64_t seed, double spread_, double sigma_, std::set<int> merged_ = {})
      : rng(seed), spread(spread_), sigma(sigma_), merged(std::move(merged_)) {}
  Vec3 a(double t) const { return Vec3(-100.0 + 10.0 * t, -spread + spread / 10.0 * t, 0.0); }
  Vec3 b(double t) const { return Vec3(-100.0 + 10.0 * t, spread - spread / 10.0 * t, 0.0); }
  Scan scan_at(int k) {
    detections.clear();
    auto add = [&](const Vec3& p, std::uint32_t origin) {
      Detection d;
      d.value = p + sigma * Vec3(rng.normal(), rng.normal(), 0.0);
      d.value(2) = 0.0;
      d.covariance = MeasCov::Identity(3, 3) * sigma * sigma;
      d.origin = origin;
      detections.push_back(d);
    };
    if (merged.count(k)) {
      add(0.5 * (a(k) + b(k)), kOriginUnknown);
    } else {
      add(a(k), 1);
      add(b(k), 2);
    }
    Scan s;
    s.time = k;
    s.sensor.frame = Frame::Cartesian;
    s.detections = detections;
    s.detection_probability = 0.95;
    s.clutter_density = 1e-9;
    return s;
  }
};

// Whether the tracks that follow A and B before the crossing (t = 6 s) follow the other one after
// it (t = 20 s): the number of tracks whose nearest target changed, and the tracks alive at both.
std::pair<int, int> swaps(const std::vector<SetCollector::Seen>& sets, const Crossing& c) {
  std::map<std::uint64_t, int> before;
  int swapped = 0, followed = 0;
  for (const auto& s : sets) {
    if (s.time != 6.0 && s.time != 20.0) continue;
    for (const TrackEstimate* t : confirmed(s)) {
      const Vec3 at = t->estimate.enu.head<3>();
      const int nearest = (at - c.a(s.time)).norm() < (at - c.b(s.time)).norm() ? 1 : 2;
      if (s.time == 6.0) {
        before[t->id] = nearest;
      } else if (before.count(t->id)) {
        ++followed;
        swapped += before[t->id] != nearest;
      }
    }
  }
  return {swapped, followed};
}

const char* kGnnCrossing =
    "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.gnn }, initiator: { type: "
    "init.m_of_n, m: 3, n: 4, start: one_point, max_speed: 50 m/s }, deleter: { type: delete.misses, max_misses: 3 } }";

std::vector<SetCollector::Seen> run_crossing(const std::string& type, const std::string& yaml, Crossing c) {
  auto n = test::make(type, yaml);
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  for (int k = 0; k <= 20; ++k) n->on_scan(c.scan_at(k), 0);
  return out.sets;
}

}  // namespace

// A shallow crossing (10 m apart at t = 0, closing at 2 m/s) with one merged detection at the
// crossing (t = 10 s): tracker.multi with assoc.gnn commits at each scan and swaps its tracks in some
// draws; the MHT carries both readings of the ambiguous scans for n_scan scans and keeps them.
// Measured over seeds 1-40: GNN 10 swapped tracks, MHT 0 (none lost by either).
TEST_CASE("a crossing that GNN swaps and the MHT keeps") {
  const std::set<int> merged{10};
  int gnn_swaps = 0, mht_swaps = 0, gnn_followed = 0, mht_followed = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Crossing c(seed, 10.0, 1.0, merged);
    const auto g = swaps(run_crossing("tracker.multi", kGnnCrossing, c), c);
    const auto m = swaps(run_crossing("tracker.tomht", tomht_yaml(), c), c);
    gnn_swaps += g.first;
    gnn_followed += g.second;
    mht_swaps += m.first;
    mht_followed += m.second;
    if (seed == 3) {  // the draw where GNN swaps both tracks
      CHECK(g == std::pair<int, int>{2, 2});
      CHECK(m == std::pair<int, int>{0, 2});
    }
  }
  CHECK(gnn_followed == 80);
  CHECK(mht_followed == 80);
  CHECK(gnn_swaps >= 6);
  CHECK(mht_swaps == 0);
}

// One global hypothesis is the GNN: the k = 1 assignment of each scan over rows = tracks, columns =
// detections + a private miss column, costs -(ln(P_D/beta) + ln N) and -ln(1 - P_D P_G), is
// assoc.gnn's matrix; free detections start tracks (one-point, velocity sigma max_speed / 2) as
// init.m_of_n's one_point start does. Confirmation differs (score against 2 of 2), so the deletion
// rules are made to coincide: every track ends at its first miss (max_misses 1 against a 2-of-2
// start and delete.misses max_misses 1; no score-based end). Then the two trackers publish the same
// ids with bit-identical estimates, and delete the same tracks at the same scans.
TEST_CASE("one hypothesis equals tracker.multi with assoc.gnn") {
  auto gnn = test::make("tracker.multi",
                        "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.gnn }, "
                        "initiator: { type: init.m_of_n, m: 2, n: 2, start: one_point, max_speed: 50 m/s }, "
                        "deleter: { type: delete.misses, max_misses: 1 } }");
  auto mht = test::make("tracker.tomht",
                        tomht_yaml("max_hypotheses: 1, n_scan: 1, max_misses: 1, score_drop: 1e12, "
                                   "true_track_loss_probability: 1e-200"));
  SetCollector a, b;
  a.attach_to(*gnn);
  b.attach_to(*mht);
  test::start_run(*gnn);
  test::start_run(*mht);
  Scenario sa, sb;
  for (int k = 0; k < 25; ++k) {
    // Clutter, and target 2 unseen at t = 8 s (its track ends and restarts in both).
    gnn->on_scan(sa.scan_at(k, 8, k != 8), 0);
    mht->on_scan(sb.scan_at(k, 8, k != 8), 0);
  }
  REQUIRE(a.sets.size() == b.sets.size());
  int compared = 0, deleted = 0;
  for (std::size_t k = 0; k < a.sets.size(); ++k) {
    INFO("scan " << k);
    REQUIRE(a.sets[k].tracks.size() == b.sets[k].tracks.size());
    for (std::size_t i = 0; i < a.sets[k].tracks.size(); ++i) {
      const TrackEstimate &x = a.sets[k].tracks[i], &y = b.sets[k].tracks[i];
      CHECK(x.id == y.id);
      CHECK((x.status == TrackStatus::Deleted) == (y.status == TrackStatus::Deleted));
      CHECK(x.hits == y.hits);
      CHECK(x.estimate.state == y.estimate.state);
      CHECK(x.estimate.covariance == y.estimate.covariance);
      ++compared;
      deleted += y.status == TrackStatus::Deleted;
    }
  }
  CHECK(compared > 100);
  CHECK(deleted > 50);  // clutter tracks, and target 2's at t = 8 s
  // The MHT confirms by its score: the two targets' tracks only. The 2-of-2 rule confirms them too,
  // and also a track on two clutter detections in a row (same ids, other status).
  CHECK(confirmed(a.sets.back()).size() >= 2);
  CHECK(confirmed(b.sets.back()).size() == 2);
}

TEST_CASE("RankedSums equals brute force best first") {
  Rng rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const int lists = 1 + trial % 4;
    std::vector<std::vector<double>> l(static_cast<std::size_t>(lists));
    tomht::RankedSums sums;
    tomht::FixedLists source;
    source.clear();
    for (auto& v : l) {
      const int n = 1 + static_cast<int>(rng.uniform() * 4);
      for (int i = 0; i < n; ++i) v.push_back(std::floor(rng.uniform() * 6));  // integers: ties and exact sums
      std::sort(v.begin(), v.end());
      source.add_list(v);
    }
    std::vector<double> all{0.0};
    for (const auto& v : l) {
      std::vector<double> next;
      for (double a : all)
        for (double x : v) next.push_back(a + x);
      all = next;
    }
    std::sort(all.begin(), all.end());
    sums.start(source);
    std::vector<double> got;
    std::set<std::vector<int>> seen;
    while (sums.next()) {
      got.push_back(sums.cost());
      const std::vector<int> idx(sums.indices().begin(), sums.indices().end());
      CHECK(seen.insert(idx).second);
      double c = 0.0;
      for (int q = 0; q < lists; ++q) c += l[static_cast<std::size_t>(q)][static_cast<std::size_t>(idx[static_cast<std::size_t>(q)])];
      CHECK(c == sums.cost());
    }
    CHECK(got == all);
  }
}

namespace {

// `count` scans of three close targets (gates overlap) and one clutter detection each.
std::vector<std::vector<Detection>> ambiguous_scans(int count = 3) {
  Rng rng(3);
  std::vector<std::vector<Detection>> scans;
  for (int k = 0; k < count; ++k) {
    std::vector<Detection> ds;
    for (int i = 0; i < 3; ++i) {
      Detection d;
      d.value = Vec3(10.0 * k, 6.0 * i, 0.0) + 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = static_cast<std::uint32_t>(i + 1);
      ds.push_back(d);
    }
    Detection c;
    c.value = Vec3(10.0 * k + 15.0, -10.0, 5.0);
    c.covariance = MeasCov::Identity(3, 3) * 4.0;
    c.origin = kOriginClutter;
    ds.push_back(c);
    scans.push_back(ds);
  }
  return scans;
}

Scan scan_of(const std::vector<Detection>& ds, double t) {
  Scan s;
  s.time = t;
  s.sensor.frame = Frame::Cartesian;
  s.detections = ds;
  s.detection_probability = 0.9;
  s.clutter_density = 1e-6;
  return s;
}

tomht::Engine make_engine(int max_hypotheses, int n_scan, int max_leaves = 100000) {
  tomht::Settings s;
  s.velocity_sigma = 10.0;
  s.max_hypotheses = max_hypotheses;
  s.n_scan = n_scan;
  s.max_leaves_per_tree = max_leaves;
  s.max_misses = 100;
  s.score_drop = 1e12;
  s.true_track_loss_probability = 1e-200;
  s.start_score = 0.7;  // not 0: a free detection's share must be counted
  const Params p = test::params_for("tracker.tomht", tomht_yaml());
  return tomht::Engine(s, p.component("estimator").create_estimator(), "test");
}

// Every compatible set of the engine's leaves (at most one per tree; every detection of every scan
// used exactly once, by a hit or as a tree's root; a tree without a leaf in the set is not in it),
// with the sum of its leaves' scores, best first.
std::vector<double> brute_force(const tomht::Engine& e, const std::vector<std::vector<Detection>>& scans, int upto) {
  const auto trees = e.trees();
  const auto leaves = e.leaves();
  const int k = e.scan_index();
  std::vector<std::vector<int>> by_tree(trees.size());
  for (std::size_t i = 0; i < leaves.size(); ++i) by_tree[static_cast<std::size_t>(leaves[i].tree)].push_back(static_cast<int>(i));
  std::set<std::pair<int, int>> used;  // (scan, detection)
  std::vector<double> out;
  std::function<void(std::size_t, double)> walk = [&](std::size_t t, double score) {
    if (t == trees.size()) {
      std::size_t all = 0;
      for (int s = 0; s < upto; ++s) all += scans[static_cast<std::size_t>(s)].size();
      if (used.size() == all) out.push_back(score);
      return;
    }
    walk(t + 1, score);  // the tree not in the set
    for (const int li : by_tree[t]) {
      const auto& l = leaves[static_cast<std::size_t>(li)];
      std::vector<std::pair<int, int>> mine;
      bool ok = true;
      for (int d = 0; d <= l.depth && ok; ++d) {
        const int j = l.recent[static_cast<std::size_t>(d)];
        if (j < 0) continue;
        const std::pair<int, int> key{k - d, j};
        if (used.count(key)) ok = false;
        else mine.push_back(key);
      }
      if (!ok) continue;
      for (const auto& key : mine) used.insert(key);
      walk(t + 1, score + l.score);
      for (const auto& key : mine) used.erase(key);
    }
  };
  walk(0, 0.0);
  std::sort(out.begin(), out.end(), std::greater<>());
  return out;
}

}  // namespace

TEST_CASE("ranked hypotheses equal brute-force leaf sets") {
  const auto scans = ambiguous_scans();
  tomht::Engine all = make_engine(100000, 10);
  for (int k = 0; k < 3; ++k) {
    INFO("scan " << k);
    all.process(scan_of(scans[static_cast<std::size_t>(k)], k));
    const std::vector<double> expected = brute_force(all, scans, k + 1);
    REQUIRE(all.hypotheses() == static_cast<int>(expected.size()));
    for (int h = 0; h < all.hypotheses(); ++h) {
      CHECK(all.hypothesis_score(h) == Approx(expected[static_cast<std::size_t>(h)]).margin(1e-9));
      // The score is the sum of the hypothesis's leaves' scores.
      double sum = 0.0;
      for (const int li : all.hypothesis_leaves(h)) sum += all.leaves()[static_cast<std::size_t>(li)].score;
      CHECK(all.hypothesis_score(h) == Approx(sum).margin(1e-9));
      if (h > 0) CHECK(all.hypothesis_score(h) <= all.hypothesis_score(h - 1));
    }
  }
  CHECK(all.hypotheses() > 1000);  // the case is ambiguous enough to test the ranking
  // With max_hypotheses 7, the first scan that needs a cut keeps exactly the 7 best (scan 1: scan 0
  // has one hypothesis, so nothing was cut before).
  tomht::Engine cut = make_engine(7, 10);
  tomht::Engine full = make_engine(100000, 10);
  for (int k = 0; k < 2; ++k) {
    cut.process(scan_of(scans[static_cast<std::size_t>(k)], k));
    full.process(scan_of(scans[static_cast<std::size_t>(k)], k));
  }
  REQUIRE(full.hypotheses() > 7);
  REQUIRE(cut.hypotheses() == 7);
  for (int h = 0; h < 7; ++h) CHECK(cut.hypothesis_score(h) == full.hypothesis_score(h));
}

TEST_CASE("determinism and non-looks and run result codec") {
  auto n = test::make("tracker.tomht", tomht_yaml());
  SetCollector out;
  out.attach_to(*n);
  auto run_once = [&](std::uint64_t run) {
    out.sets.clear();
    test::start_run(*n, run);
    Scenario sc;
    for (int k = 0; k < 12; ++k) {
      Scan s = sc.scan_at(k, 6, k != 6);
      if (k == 9) s.valid = false;  // not a look: the same tracks, nothing missed
      n->on_scan(s, 0);
    }
    return out.sets;
  };
  const auto first = run_once(0);
  std::unique_ptr<RunResult> r = n->end_run();
  const auto again = run_once(0);  // the same node again: spares and storage from the first run
  REQUIRE(again.size() == first.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    REQUIRE(again[k].tracks.size() == first[k].tracks.size());
    for (std::size_t i = 0; i < first[k].tracks.size(); ++i) {
      const TrackEstimate &a = first[k].tracks[i], &b = again[k].tracks[i];
      CHECK(a.id == b.id);
      CHECK(a.status == b.status);
      CHECK(a.score == b.score);
      CHECK(a.estimate.state == b.estimate.state);
      CHECK(a.estimate.covariance == b.estimate.covariance);
    }
  }
  // The non-look: the previous set's live tracks at the new time, misses unchanged.
  REQUIRE(first[9].tracks.size() >= 2);
  for (const TrackEstimate& t : first[9].tracks) {
    CHECK(t.estimate.time == 9.0);
    CHECK(t.status != TrackStatus::Deleted);
  }
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
  CHECK(s.find("tracks_confirmed_per_run")->value >= 2.0);
  CHECK(s.find("scans")->value == 12.0);
  CHECK(s.find("scans_not_looked")->value == 1.0);
  CHECK(s.find("hypotheses_per_scan")->value > 1.0);
  CHECK(s.find("hypotheses_per_scan")->value <= 100.0);
  CHECK(s.find("leaves_per_scan")->value > 2.0);
  CHECK(s.find("pruned_leaves")->value > 0.0);
}

TEST_CASE("configuration errors") {
  CHECK_THROWS_WITH(test::make("tracker.tomht", tomht_yaml("false_track_probability: 0.5, true_track_loss_probability: 0.5")),
                    Catch::Contains("must be below 1"));
  CHECK_THROWS(test::make("tracker.tomht", tomht_yaml("n_scan: 40")));
  CHECK_THROWS(test::make("tracker.tomht", "{ estimator: { type: filter.kalman } }"));  // max_speed required
}

// After each scan: at most max_hypotheses hypotheses, scores non-increasing; every hypothesis
// agrees with the best one at scan k - N (each leaf of a tree born by then has the best
// hypothesis's detection of that scan; a tree the best one lacks is not older than that); at most
// max_leaves_per_tree leaves per tree, each used by some hypothesis.
TEST_CASE("N-scan pruning and the leaf bound hold after every scan") {
  const auto scans = ambiguous_scans(8);
  for (const int N : {0, 1, 2}) {
    INFO("n_scan " << N);
    tomht::Engine e = make_engine(30, N, 4);
    int pruned_somewhere = 0;
    for (int k = 0; k < 8; ++k) {
      e.process(scan_of(scans[static_cast<std::size_t>(k)], k));
      REQUIRE(e.hypotheses() >= 1);
      CHECK(e.hypotheses() <= 30);
      const int scan = e.scan_index();
      std::map<int, int> best_leaf;  // tree -> leaf in the best hypothesis
      for (const int li : e.hypothesis_leaves(0)) best_leaf[e.leaves()[static_cast<std::size_t>(li)].tree] = li;
      std::vector<int> used(e.leaves().size(), 0);
      for (int h = 0; h < e.hypotheses(); ++h) {
        if (h > 0) CHECK(e.hypothesis_score(h) <= e.hypothesis_score(h - 1));
        for (const int li : e.hypothesis_leaves(h)) {
          ++used[static_cast<std::size_t>(li)];
          const auto& l = e.leaves()[static_cast<std::size_t>(li)];
          const auto& t = e.trees()[static_cast<std::size_t>(l.tree)];
          if (t.birth_scan > scan - N) continue;
          REQUIRE(best_leaf.count(l.tree));
          CHECK(l.recent[static_cast<std::size_t>(N)] ==
                e.leaves()[static_cast<std::size_t>(best_leaf[l.tree])].recent[static_cast<std::size_t>(N)]);
        }
      }
      std::map<int, int> per_tree;
      for (std::size_t i = 0; i < e.leaves().size(); ++i) {
        CHECK(used[i] > 0);
        ++per_tree[e.leaves()[i].tree];
      }
      for (const auto& [tree, n] : per_tree) CHECK(n <= 4);
      pruned_somewhere += e.counters().pruned_hypotheses > 0;
    }
    CHECK(pruned_somewhere > 0);  // the bounds did act
  }
}

// A cluster above max_cluster_trees is given its best assignment only, and counted: with the bound
// at 1 every cluster of two or more trees is capped, the run still tracks both targets, and the
// summary says how many rankings were cut.
TEST_CASE("big clusters get their best assignment only") {
  auto n = test::make("tracker.tomht", tomht_yaml("max_cluster_trees: 1"));
  SetCollector out;
  out.attach_to(*n);
  test::start_run(*n);
  Scenario sc;
  for (int k = 0; k < 20; ++k) n->on_scan(sc.scan_at(k, 20), 0);
  REQUIRE(out.sets.size() == 20);
  CHECK(confirmed(out.sets.back()).size() == 2);
  std::unique_ptr<RunResult> r = n->end_run();
  n->merge(*r);
  Summary s;
  n->finish(s, FinishContext{});
  REQUIRE(s.find("clusters_capped"));
  CHECK(s.find("clusters_capped")->value > 0.0);
  // Unbounded (the default 30 here): nothing capped.
  auto m = test::make("tracker.tomht", tomht_yaml());
  test::start_run(*m);
  Scenario sc2;
  for (int k = 0; k < 20; ++k) m->on_scan(sc2.scan_at(k, 20), 0);
  std::unique_ptr<RunResult> r2 = m->end_run();
  m->merge(*r2);
  Summary s2;
  m->finish(s2, FinishContext{});
  CHECK_FALSE(s2.find("clusters_capped"));
}
