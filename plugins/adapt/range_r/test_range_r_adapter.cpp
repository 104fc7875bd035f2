// Purpose: tests of adapt.range_r attached to filter.ekf: the R it writes, its annotation and summary, and its refusal on a Cartesian filter.
#include "range_law.hpp"

#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/graph.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <string>

using namespace trackflow;

namespace {

Measurement spherical(double t, double r, double az, double el) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Spherical;
  m.value = MeasVec(3);
  m.value << r, az, el;
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() << 4.0, 1e-8, 1e-8;
  m.covariance(1, 2) = m.covariance(2, 1) = 5e-9;  // a correlation the adapter must remove
  return m;
}

}  // namespace

// Before each update the filter's R holds the measurement's range variance and R(r) on both angles.
TEST_CASE("writes R of the measured range into the angles") {
  auto filter = test::make("filter.ekf", "{ q: 1 m2/s3 }", "ekf");
  auto adapter = test::make("adapt.range_r", "{ alpha: 400 urad2, beta: 900 urad2, reference_range: 100 km }", "arr");
  auto* f = dynamic_cast<Filter*>(filter.get());
  auto* a = dynamic_cast<Adapter*>(adapter.get());
  test::attach(*a, *f);
  test::Collector out;
  out.attach_to(*filter);
  Diagnostics d;
  filter->start_run({0, 1, &d});
  adapter->start_run({0, 1, &d});
  const adapt::RangeLaw law{400e-12, 900e-12, 100e3};
  for (int k = 0; k < 5; ++k) {
    const double r = 50e3 + 2e3 * k;
    filter->on_measurement(spherical(0.1 * k, r, 0.5, 0.2), 0);
    const MeasCov& R = *f->noise().measurement.R;
    CHECK(R(0, 0) == 4.0);
    CHECK(R(1, 1) == Approx(law.variance(r)).epsilon(1e-14));
    CHECK(R(2, 2) == Approx(law.variance(r)).epsilon(1e-14));
    CHECK(R(1, 2) == 0.0);
    REQUIRE(out.estimates.back().annotation_count == 1);
    CHECK(out.estimates.back().annotations[0] == Approx(std::sqrt(law.variance(r))).epsilon(1e-14));
  }
  // An invalid measurement is not touched (the filter coasts; R is the measurement's own).
  Measurement bad = spherical(1.0, 60e3, 0.5, 0.2);
  bad.valid = false;
  filter->on_measurement(bad, 0);
  CHECK((*f->noise().measurement.R)(1, 1) == 1e-8);
}

// A target receding radially at 1 km/s from 20 to 60 km (range noise 0): sigma_of_mean_r is the square
// root of the mean of R(r_k) over the 41 x 4 updates (runs x samples), computed here from the known ranges.
TEST_CASE("reports the mean R a fixed filter would use") {
  const std::string yaml = R"(
pipeline: { name: range_r, seed: 3, runs: 4 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 1 Hz
      initial_position: [20 km, 0 km, 0 km]
      initial_velocity: [1000 m/s, 0 m/s, 0 m/s]
      segments: [{ type: constant_velocity, duration: 40 s }]
  - id: radar
    type: sim.radar
    input: truth
    params: { sigma_range: 0 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad }
  - { id: ekf, type: filter.ekf, input: radar, params: { q: 1 m2/s3 } }
  - { id: arr, type: adapt.range_r, attach_to: ekf, params: { alpha: 400 urad2, beta: 900 urad2, reference_range: 30 km } }
)";
  host::PipelineConfig cfg = host::parse_pipeline(host::load_yaml_string(yaml, "test.yaml"), "test.yaml");
  const host::Graph g = host::build_graph(cfg, test::registry());
  host::RunOptions opt;
  opt.runs = cfg.runs;
  opt.seed = cfg.seed;
  opt.threads = 2;
  const host::Outcome o = host::run_graph(g, test::registry(), opt);
  const Summary& s = o.find("arr")->summary;
  const adapt::RangeLaw law{400e-12, 900e-12, 30e3};
  double sum = 0, thermal = 0;
  for (int k = 0; k <= 40; ++k) {
    sum += law.variance(20e3 + 1e3 * k);
    thermal += law.thermal(20e3 + 1e3 * k);
  }
  REQUIRE(s.find("updates"));
  CHECK(s.find("updates")->value == 4 * 41);
  CHECK(s.find("sigma_of_mean_r")->value == Approx(std::sqrt(sum / 41)).epsilon(1e-12));
  CHECK(s.find("thermal_fraction")->value == Approx(thermal / sum).epsilon(1e-12));
  CHECK(s.find("sigma_min")->value == Approx(std::sqrt(law.variance(law.minimum_range()))).epsilon(1e-3));
  CHECK(s.find("sigma_max")->value == Approx(std::sqrt(law.variance(60e3))).epsilon(1e-12));
}

// The typed contract: R in spherical measurement space. filter.kalman's R is Cartesian: refused when
// the pipeline is built, at the adapter's attach_to line, naming both spaces.
TEST_CASE("refused on a cartesian filter at validate time") {
  const std::string yaml = R"(
pipeline: { name: range_r_bad, seed: 3, runs: 1 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 1 Hz
      initial_position: [20 km, 0 km, 0 km]
      segments: [{ type: constant_velocity, duration: 10 s }]
  - { id: radar, type: sim.radar, input: truth }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm }
  - { id: arr, type: adapt.range_r, attach_to: kf, params: { alpha: 400 urad2, beta: 900 urad2, reference_range: 30 km } }
)";
  host::PipelineConfig cfg = host::parse_pipeline(host::load_yaml_string(yaml, "bad.yaml"), "bad.yaml");
  try {
    host::build_graph(cfg, test::registry());
    FAIL("adapt.range_r attached to filter.kalman was accepted");
  } catch (const ConfigError& e) {
    const std::string what = e.message();
    CHECK_THAT(what, Catch::Contains("bad.yaml:13:") && Catch::Contains("'arr'") && Catch::Contains("spherical") &&
                         Catch::Contains("receives cartesian measurements"));
  }
  CHECK_THROWS_WITH(test::make("adapt.range_r", "{ alpha: 0 urad2, beta: 0 urad2, reference_range: 1 km }"),
                    Catch::Contains("beta"));
  CHECK_THROWS_AS(test::make("adapt.range_r", "{ alpha: 1 mrad, beta: 1 urad2, reference_range: 1 km }"), ConfigError);
}
