// Purpose: tests of sink.angle_error: per-interval RMS and mean of known angle errors for measurements and filters, overlapping and half-open intervals, azimuth wrap, misses, wiring.
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

const Vec3 kRadar(100.0, -50.0, 10.0);

std::vector<InputInfo> inputs() {
  return {{"truth", "sim.trajectory", mask(ItemKind::Truth), {}},
          {"radar", "sim.monopulse_radar", mask(ItemKind::Measurement), {}},
          {"kf", "filter.ekf", mask(ItemKind::Estimate), {}}};
}

Truth truth(double t, const Vec3& p) {
  Truth x;
  x.time = t;
  x.position = p;
  return x;
}

Measurement measurement(double t, double r, double az, double el, bool valid = true) {
  Measurement m;
  m.time = t;
  m.valid = valid;
  m.sensor_position = kRadar;
  m.value = MeasVec(3);
  m.value << r, az, el;
  m.covariance = MeasCov::Identity(3, 3);
  return m;
}

Estimate estimate(double t, const Vec3& p) {
  Estimate e;
  e.time = t;
  e.initialised = true;
  e.enu << p, Vec3::Zero();
  return e;
}

const Metric& metric(const Summary& s, const std::string& name) {
  const Metric* m = s.find(name);
  REQUIRE(m);
  return *m;
}

}  // namespace

// A target at (r, az, el) from the radar; the measurement is off by +da in azimuth and -de in elevation at
// t < 1 s and by -da, +de later; the filter's position is the target moved along the azimuth direction
// by an angle db. Intervals [0, 2) (both halves: RMS da, mean 0) and [0, 1) (mean +da) overlap; the
// sample at t = 2 s belongs to no interval (half-open).
TEST_CASE("rms and mean of known errors per interval") {
  auto sink = test::make("sink.angle_error", "{ intervals: [{start: 0 s, end: 2 s}, {start: 0 s, end: 1 s}] }", "angles");
  sink->set_inputs(inputs());
  const double r = 20e3, az = 0.6, el = 0.3, da = 200e-6, de = 100e-6, db = 50e-6;
  for (int run = 0; run < 2; ++run) {
    Diagnostics d;
    sink->start_run({static_cast<std::uint64_t>(run), 1, &d});
    for (int k = 0; k <= 4; ++k) {
      const double t = 0.5 * k;
      const Vec3 p = kRadar + spherical_to_enu(r, az, el, AzimuthConvention::NorthClockwise);
      // Estimates before the measurement and the truth (the order a pipeline may deliver them in).
      sink->on_estimate(estimate(t, kRadar + spherical_to_enu(r, az + db, el, AzimuthConvention::NorthClockwise)), 2);
      const double s = t < 1.0 ? 1.0 : -1.0;
      sink->on_measurement(measurement(t, r, az + s * da, el - s * de), 1);
      sink->on_truth(truth(t, p), 0);
    }
    auto result = sink->end_run();
    sink->merge(*result);
  }
  Summary s;
  sink->finish(s, {"angles", "", 2});
  CHECK(metric(s, "az_rms_radar_0_2").value == Approx(200.0).epsilon(1e-9));
  CHECK(metric(s, "az_rms_radar_0_2").unit == "urad");
  CHECK(metric(s, "az_mean_radar_0_2").value == Approx(0.0).margin(1e-9));
  CHECK(metric(s, "el_rms_radar_0_2").value == Approx(100.0).epsilon(1e-9));
  CHECK(metric(s, "az_mean_radar_0_1").value == Approx(200.0).epsilon(1e-9));
  CHECK(metric(s, "el_mean_radar_0_1").value == Approx(-100.0).epsilon(1e-9));
  CHECK(metric(s, "az_mean_kf_0_2").value == Approx(50.0).epsilon(1e-7));
  CHECK(metric(s, "az_rms_kf_0_1").value == Approx(50.0).epsilon(1e-7));
  CHECK(metric(s, "el_mean_kf_0_2").value == Approx(0.0).margin(1e-6));
  // The series holds the sample counts: 2 runs x 4 looks in [0, 2), the t = 2 s one left out.
  REQUIRE(s.series.size() == 1);
  const Series& t = s.series[0];
  const int samples = t.column("radar_samples");
  REQUIRE(samples >= 0);
  CHECK(t.at(0, static_cast<std::size_t>(samples)) == 8);
  CHECK(t.at(1, static_cast<std::size_t>(samples)) == 4);
}

// An azimuth measured just across +-pi from the truth is an error of 2 x 100 urad, not 2 pi.
TEST_CASE("azimuth errors are wrapped") {
  auto sink = test::make("sink.angle_error", "{ intervals: [{start: 0 s, end: 1 s}] }", "angles");
  sink->set_inputs(inputs());
  Diagnostics d;
  sink->start_run({0, 1, &d});
  const double pi = std::numbers::pi;
  sink->on_truth(truth(0, kRadar + spherical_to_enu(30e3, pi - 100e-6, 0.2, AzimuthConvention::NorthClockwise)), 0);
  sink->on_measurement(measurement(0, 30e3, -pi + 100e-6, 0.2), 1);
  auto result = sink->end_run();
  sink->merge(*result);
  Summary s;
  sink->finish(s, {"angles", "", 1});
  CHECK(metric(s, "az_mean_radar_0_1").value == Approx(200.0).epsilon(1e-6));
}

// Invalid measurements (missed looks) are counted, not scored.
TEST_CASE("missed looks are counted not scored") {
  auto sink = test::make("sink.angle_error", "{ intervals: [{start: 0 s, end: 10 s}] }", "angles");
  sink->set_inputs(inputs());
  Diagnostics d;
  sink->start_run({0, 1, &d});
  for (int k = 0; k < 4; ++k) {
    sink->on_truth(truth(k, kRadar + spherical_to_enu(30e3, 0.5, 0.2, AzimuthConvention::NorthClockwise)), 0);
    sink->on_measurement(measurement(k, 30e3, 0.5 + (k == 2 ? 1.0 : 1e-4), 0.2, k != 2), 1);
  }
  auto result = sink->end_run();
  sink->merge(*result);
  Summary s;
  sink->finish(s, {"angles", "", 1});
  CHECK(metric(s, "az_rms_radar_0_10").value == Approx(100.0).epsilon(1e-6));
  CHECK(metric(s, "missed_radar").value == 1);
}

TEST_CASE("wiring and data it cannot score are refused") {
  auto sink = test::make("sink.angle_error", "{ intervals: [{start: 0 s, end: 1 s}] }", "angles");
  CHECK_THROWS_AS(sink->set_inputs({inputs()[1], inputs()[2]}), ConfigError);  // no truth
  auto only_truth = test::make("sink.angle_error", "{ intervals: [{start: 0 s, end: 1 s}] }", "angles");
  CHECK_THROWS_AS(only_truth->set_inputs({inputs()[0]}), ConfigError);
  CHECK_THROWS_AS(test::make("sink.angle_error", "{ intervals: [{start: 2 s, end: 1 s}] }"), ConfigError);
  CHECK_THROWS_AS(test::make("sink.angle_error", "{}"), ConfigError);
  sink->set_inputs(inputs());
  Diagnostics d;
  sink->start_run({0, 1, &d});
  Measurement cartesian = measurement(0, 1, 2, 3);
  cartesian.frame = Frame::Cartesian;
  CHECK_THROWS_AS(sink->on_measurement(cartesian, 1), DataError);
}
