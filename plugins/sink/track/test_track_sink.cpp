// Purpose: tests of sink.track: only the chosen run is recorded, one series per stream, estimates before initialisation left out.
#include <catch2/catch.hpp>

#include <cmath>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

const std::vector<InputInfo> kInputs = {{"truth", "sim.trajectory", mask(ItemKind::Truth)},
                                        {"cm", "convert.classical", mask(ItemKind::Measurement)},
                                        {"kf", "filter.kalman", mask(ItemKind::Estimate)}};

void feed(Component& c, int run) {
  for (int k = 0; k < 3; ++k) {
    const double t = 0.1 * k;
    Truth tr;
    tr.time = t;
    tr.position = Vec3(100.0 * run + k, 0, 0);
    c.on_truth(tr, 0);
    Measurement m;
    m.time = t;
    m.frame = Frame::Cartesian;
    m.value = MeasVec::Constant(3, 1.0 + k);
    m.covariance = MeasCov::Identity(3, 3) * 4.0;
    c.on_measurement(m, 1);
    Estimate e;
    e.time = t;
    e.initialised = k > 0;
    e.enu = Vec6::Constant(7.0);
    e.enu_covariance = Mat6::Identity() * 9.0;
    c.on_estimate(e, 2);
  }
}

}  // namespace

TEST_CASE("sink.track keeps only the chosen run") {
  auto worker = test::make("sink.track", "{ run: 1 }", "track");
  auto aggregate = test::make("sink.track", "{ run: 1 }", "track");
  worker->set_inputs(kInputs);
  aggregate->set_inputs(kInputs);
  Diagnostics diag;
  int results = 0;
  for (int r = 0; r < 3; ++r) {
    worker->start_run({static_cast<std::uint64_t>(r), 1, &diag});
    feed(*worker, r);
    if (auto res = worker->end_run()) {
      ++results;
      aggregate->merge(*res);
    }
  }
  CHECK(results == 1);
  Summary s;
  aggregate->finish(s, {"track", "", 3});
  REQUIRE(s.series.size() == 3);
  CHECK(s.series[0].name == "truth:truth");
  CHECK(s.series[1].name == "measurement:cm");
  CHECK(s.series[2].name == "estimate:kf");
  const Series& truth = s.series[0];
  REQUIRE(truth.rows() == 3);
  CHECK(truth.at(2, truth.column("x")) == 102.0);  // run 1's truth, not run 0's or 2's
  CHECK(truth.columns[truth.column("x")].unit == "m");
  const Series& meas = s.series[1];
  CHECK(meas.at(0, meas.column("sigma_y")) == 2.0);
  CHECK(s.series[2].rows() == 2);  // the uninitialised estimate is left out
  CHECK(s.series[2].at(0, s.series[2].column("sigma_z")) == 3.0);
}

TEST_CASE("sink.track notes a run that never ran") {
  auto aggregate = test::make("sink.track", "{ run: 5 }", "track");
  aggregate->set_inputs(kInputs);
  Summary s;
  aggregate->finish(s, {"track", "", 2});
  CHECK(s.series.empty());
  REQUIRE(s.notes.size() == 1);
  CHECK(s.notes[0].find("run 5") != std::string::npos);
}
