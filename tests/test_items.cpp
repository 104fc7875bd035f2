// Purpose: tests of the SDK items: a Measurement is a SensorFrame plus a Detection without a copy, scans and track sets reach exactly the links that accept them, state components are found by name.
#include <trackflow/component.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace trackflow;

namespace {

// Records what reached it, per item kind and port.
struct Recorder final : Component {
  std::vector<std::string> got;
  void on_truth(const Truth&, int port) override { got.push_back("truth@" + std::to_string(port)); }
  void on_measurement(const Measurement&, int port) override { got.push_back("measurement@" + std::to_string(port)); }
  void on_estimate(const Estimate&, int port) override { got.push_back("estimate@" + std::to_string(port)); }
  void on_scan(const Scan& s, int port) override {
    got.push_back("scan@" + std::to_string(port) + ":" + std::to_string(s.detections.size()));
  }
  void on_tracks(const TrackSet& t, int port) override {
    got.push_back("tracks@" + std::to_string(port) + ":" + std::to_string(t.tracks.size()));
  }
};

}  // namespace

TEST_CASE("a measurement binds to its sensor frame and detection") {
  Measurement m;
  m.sensor = 7;
  m.sensor_position = Vec3(1, 2, 3);
  m.value = MeasVec::Constant(3, 4.0);
  m.origin = 2;
  const SensorFrame& f = m;
  const Detection& d = m;
  CHECK(&f.sensor_position == &m.sensor_position);
  CHECK(&d.value == &m.value);
  CHECK(f.sensor == 7);
  CHECK(d.origin == 2);
  CHECK(Detection{}.origin == kOriginUnknown);
}

TEST_CASE("scans and track sets reach only the links that accept them") {
  Recorder scans_only, everything;
  const Link links[] = {{&scans_only, 1, mask(ItemKind::Scan)},
                        {&everything, 0, static_cast<ItemMask>(0xFF)}};
  Outputs out;
  out.connect(links, 2);
  Detection dets[3];
  Scan s;
  s.detections = dets;
  out.emit(s);
  Scan empty;  // the radar looked and saw nothing: still delivered
  out.emit(empty);
  TrackEstimate tracks[2];
  out.emit(TrackSet{1.0, tracks});
  out.emit(Truth{});
  CHECK(scans_only.got == std::vector<std::string>{"scan@1:3", "scan@1:0"});
  CHECK(everything.got == std::vector<std::string>{"scan@0:3", "scan@0:0", "tracks@0:2", "truth@0"});
}

TEST_CASE("item kinds and track statuses have names") {
  std::vector<std::string> names;
  for (ItemKind k : kItemKinds) names.push_back(to_string(k));
  CHECK(names == std::vector<std::string>{"truth", "measurement", "estimate", "scan", "tracks"});
  CHECK(std::string(to_string(TrackStatus::Coasting)) == "coasting");
}

TEST_CASE("state components are found by name") {
  const StateComponent c[3] = {{"x", "m"}, {"vx", "m/s"}, {"bias", "rad"}};
  const StateLayout layout{c, 3};
  CHECK(layout.index_of("bias") == 2);
  CHECK(layout.index_of("x") == 0);
  CHECK(layout.index_of("b") == -1);
  CHECK(StateLayout{}.index_of("x") == -1);
}

TEST_CASE("a surveillance region's volume is the product of its extents") {
  SurveillanceRegion r;
  r.dim = 2;
  r.hi[0] = 1000.0;
  r.hi[1] = 2.0;
  CHECK(r.volume() == Approx(2000.0));
  r.dim = 3;
  r.lo[2] = -0.5;
  r.hi[2] = 0.5;
  CHECK(r.volume() == Approx(2000.0));
}
