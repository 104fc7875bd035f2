// Purpose: tests of sink.interval_rmse on synthetic estimates, spherical measurements and truth: per-interval RMSE against hand values, ratios, wiring errors.
#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include <cmath>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

const Vec3 kSensor(1000.0, -2000.0, 0.0);

// 30 samples at 1 Hz; truth at 20 km east of the sensor moving north. The filter is off by
// f(t) m in z; the radar measures the range `m(t)` m long (angles exact), so its ENU error is m(t).
template <class F, class M>
void feed(Component& sink, std::uint64_t run, F f, M m) {
  Diagnostics d;
  sink.start_run({run, 1, &d});
  for (int k = 0; k < 30; ++k) {
    const double t = k;
    Truth truth;
    truth.time = t;
    truth.position = kSensor + Vec3(20e3, 50.0 * t, 3e3);
    sink.on_truth(truth, 1);
    Measurement meas;
    meas.time = t;
    meas.sensor_position = kSensor;
    const Vec3 rae = enu_to_spherical(truth.position - kSensor, AzimuthConvention::NorthClockwise);
    meas.value = MeasVec(3);
    meas.value << rae(0) + m(t), rae(1), rae(2);
    meas.covariance = MeasCov::Identity(3, 3);
    meas.valid = k != 7;  // an unlocked sample is not scored
    sink.on_measurement(meas, 2);
    Estimate e;
    e.time = t;
    e.initialised = k >= 2;
    e.enu.setZero();
    e.enu.head<3>() = truth.position + Vec3(0, 0, f(t));
    e.enu_covariance.setIdentity();
    sink.on_estimate(e, 0);
  }
  auto r = sink.end_run();
  sink.merge(*r);
}

double metric(const Summary& s, const std::string& name) {
  INFO(name);
  const Metric* m = s.find(name);
  REQUIRE(m);
  return m->value;
}

}  // namespace

// per-interval filter and measurement RMSE, ratios and the largest ratio over two runs
TEST_CASE("per-interval RMSE and ratios over two runs") {
  auto sink = test::make("sink.interval_rmse", "{ interval: 10 s }");
  feed(*sink, 0, [](double t) { return t < 10 ? 2.0 : 1.0; }, [](double t) { return t < 20 ? 4.0 : 0.5; });
  feed(*sink, 1, [](double t) { return t < 10 ? -4.0 : 1.0; }, [](double t) { return t < 20 ? -2.0 : 0.5; });
  Summary s;
  sink->finish(s, {"iv", "", 2});
  // Interval 0: filter samples t = 2..9 (initialised from k = 2), errors 2 and 4; measurements
  // t = 0..9 without t = 7, errors 4 and 2.
  CHECK(metric(s, "filter_rmse_0s") == Approx(std::sqrt((4.0 + 16.0) / 2.0)));
  CHECK(metric(s, "measurement_rmse_0s") == Approx(std::sqrt((16.0 + 4.0) / 2.0)).epsilon(1e-6));
  CHECK(metric(s, "filter_rmse_10s") == Approx(1.0));
  CHECK(metric(s, "measurement_rmse_10s") == Approx(std::sqrt(10.0)).epsilon(1e-6));
  CHECK(metric(s, "ratio_20s") == Approx(2.0).epsilon(1e-6));
  CHECK(metric(s, "max_ratio") == Approx(2.0).epsilon(1e-6));
  CHECK(metric(s, "intervals") == 3);
  CHECK(metric(s, "non_finite_estimates") == 0);
}

// skip_initial and start move the intervals; the wiring must be one filter and one measurement stream
TEST_CASE("skip_initial/start and the required wiring") {
  auto sink = test::make("sink.interval_rmse", "{ interval: 10 s, start: 5 s, skip_initial: 3 s }");
  feed(*sink, 0, [](double t) { return t; }, [](double) { return 1.0; });
  Summary s;
  sink->finish(s, {"iv", "", 1});
  // First estimate at t = 2, so items from t = 5 on: [5, 15) holds filter errors 5..14.
  double sq = 0;
  for (int t = 5; t < 15; ++t) sq += t * t;
  CHECK(metric(s, "filter_rmse_5s") == Approx(std::sqrt(sq / 10)));
  CHECK(s.find("filter_rmse_m5s") == nullptr);
  CHECK(metric(s, "intervals") == 3);  // [5,15), [15,25), [25,35)

  const std::vector<InputInfo> no_measurements = {{"kf", "filter.ekf", mask(ItemKind::Estimate)},
                                                  {"truth", "sim.trajectory", mask(ItemKind::Truth)}};
  CHECK_THROWS_AS(sink->set_inputs(no_measurements), ConfigError);
}
