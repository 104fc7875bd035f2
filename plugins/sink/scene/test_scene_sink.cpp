// Purpose: tests of sink.scene: only the chosen run is recorded, truths / tracks / detections with their ids and origins, clutter thinned by scan past max_points (and said), the codec.
#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "plugin_fixture.hpp"
#include "scoring/track_set_fixture.hpp"

using namespace trackflow;

namespace {

std::shared_ptr<Component> make(const std::string& yaml) {
  auto s = test::make("sink.scene", yaml);
  s->set_inputs({{"scenario", "sim.scenario", ItemKind::Truth | ItemKind::Scan, {}},
                 {"gnn", "tracker.multi", mask(ItemKind::Tracks), {}}});
  return s;
}

Detection cartesian(double x, double y, std::uint32_t origin) {
  Detection d;
  d.origin = origin;
  d.value.resize(3);
  d.value << x, y, 0.0;
  d.covariance = MeasCov::Identity(3, 3);
  return d;
}

// Scan k at t = k s: one target detection and `clutter` false alarms; a truth and a track.
void scan(Component& s, int k, int clutter) {
  std::vector<Detection> dets{cartesian(k, 0, 0)};
  for (int c = 0; c < clutter; ++c) dets.push_back(cartesian(100 + c, 50, kOriginClutter));
  s.on_truth(test::truth(k, 0, Vec3(k, 0, 0)), 0);
  Scan sc;
  sc.time = k;
  sc.sensor.frame = Frame::Cartesian;
  sc.detections = dets;
  s.on_scan(sc, 0);
  std::vector<TrackEstimate> tracks{test::track(7, Vec3(k, 1, 0), k < 2 ? TrackStatus::Tentative : TrackStatus::Confirmed)};
  s.on_tracks(TrackSet{double(k), tracks}, 1);
}

const Series* find(const Summary& s, const std::string& name) {
  for (const auto& x : s.series)
    if (x.name == name) return &x;
  return nullptr;
}

}  // namespace

TEST_CASE("sink.scene records the chosen run only") {
  auto s = make("{ run: 1 }");
  for (int run = 0; run < 3; ++run) {
    test::start_run(*s, run);
    for (int k = 0; k < 4; ++k) scan(*s, k, run + 1);
    if (auto r = s->end_run()) s->merge(*r);
  }
  Summary sum;
  s->finish(sum, {});
  const Series* truth = find(sum, "truth:scenario");
  const Series* dets = find(sum, "scan:scenario");
  const Series* tracks = find(sum, "tracks:gnn");
  REQUIRE(truth);
  REQUIRE(dets);
  REQUIRE(tracks);
  CHECK(truth->rows() == 4);
  CHECK(dets->rows() == 4 * 3);  // run 1: one target detection and 2 clutter per scan
  CHECK(dets->at(0, dets->column("origin")) == 0.0);
  CHECK(dets->at(1, dets->column("origin")) == -1.0);
  CHECK(tracks->rows() == 4);
  CHECK(tracks->at(0, tracks->column("track")) == 7.0);
  CHECK(tracks->at(0, tracks->column("status")) == 0.0);
  CHECK(tracks->at(3, tracks->column("status")) == 1.0);
  CHECK(test::metric(sum, "clutter_scan_stride") == 1.0);
}

TEST_CASE("sink.scene thins clutter by scan past max_points") {
  auto s = make("{ max_points: 100 }");
  test::start_run(*s, 0);
  for (int k = 0; k < 20; ++k) scan(*s, k, 10);  // 20 x (1 truth + 11 detections + 1 track) = 260
  const Summary sum = test::finish_run(*s);
  const double stride = test::metric(sum, "clutter_scan_stride");
  CHECK(stride >= 4.0);
  CHECK(test::metric(sum, "points_not_recorded") == 0.0);
  const Series* dets = find(sum, "scan:scenario");
  REQUIRE(dets);
  int targets = 0;
  for (size_t r = 0; r < dets->rows(); ++r) {
    if (dets->at(r, dets->column("origin")) == 0.0) ++targets;
    else CHECK(static_cast<long>(dets->at(r, dets->column("scan"))) % static_cast<long>(stride) == 0);
  }
  CHECK(targets == 20);  // target-originated detections are all kept
  bool noted = false;
  for (const auto& n : sum.notes) noted |= n.find("clutter of every") != std::string::npos;
  CHECK(noted);
}

TEST_CASE("sink.scene counts what does not fit without clutter") {
  auto s = make("{ max_points: 100 }");
  test::start_run(*s, 0);
  for (int k = 0; k < 40; ++k) scan(*s, k, 0);  // 40 x 3 points, no clutter to thin
  const Summary sum = test::finish_run(*s);
  CHECK(test::metric(sum, "points_not_recorded") == 20.0);
}

TEST_CASE("sink.scene: clutter of the first scan only is not thinned") {
  auto s = make("{ max_points: 100 }");
  test::start_run(*s, 0);
  scan(*s, 0, 50);                           // 53 points, the clutter of scan 0 kept at any stride
  for (int k = 1; k < 40; ++k) scan(*s, k, 0);  // 3 a scan: 47 more fit, 70 do not
  const Summary sum = test::finish_run(*s);
  CHECK(test::metric(sum, "points_not_recorded") == 70.0);
  CHECK(test::metric(sum, "clutter_scan_stride") == 1.0);
}

TEST_CASE("sink.scene: the run result survives the codec") {
  test::check_codec_round_trip([] { return make("{}"); }, [](Component& s, int) {
    for (int k = 0; k < 3; ++k) scan(s, k, 2);
  });
}
