// Purpose: tests of sink.elevation_error: errors in degrees over an elevation band and from a time, per run and over runs, the bias estimate against the true Clark bias, and the wiring checks.
#include "physics/refraction.hpp"

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

constexpr double kDeg = std::numbers::pi / 180;
constexpr int kBiasAt = 12;  // where the test layout (kLayout) has the bias

// The true target at elevation el(t) = 12 - 0.1 t deg, 1000 km from the radar at the origin.
double true_el(double t) { return (12.0 - 0.1 * t) * kDeg; }
Truth truth_at(double t) {
  Truth x;
  x.time = t;
  x.position = Vec3(0.0, 1e6 * std::cos(true_el(t)), 1e6 * std::sin(true_el(t)));
  return x;
}
Measurement measurement_at(double t, double error) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Spherical;
  m.value = MeasVec::Zero(3);
  m.value << 1e6, 0.0, true_el(t) + error;
  m.covariance = MeasCov::Identity(3, 3);
  return m;
}
Estimate estimate_at(double t, double error, double bias) {
  Estimate e;
  e.time = t;
  e.initialised = true;
  e.state = StateVec::Zero(13);
  e.state(kBiasAt) = bias;
  e.enu.setZero();
  e.enu.head<3>() = Vec3(0.0, 1e6 * std::cos(true_el(t) + error), 1e6 * std::sin(true_el(t) + error));
  return e;
}

Summary score(const std::string& yaml, const std::vector<InputInfo>& inputs, int runs,
              const std::function<void(Component&, int run)>& feed) {
  auto agg = test::make("sink.elevation_error", yaml);
  agg->set_inputs(inputs);
  for (int r = 0; r < runs; ++r) {
    auto s = test::make("sink.elevation_error", yaml);
    s->set_inputs(inputs);
    Diagnostics d;
    s->start_run({static_cast<std::uint64_t>(r), 1, &d});
    feed(*s, r);
    auto res = s->end_run();
    agg->merge(*res);
  }
  Summary sum;
  agg->finish(sum, {"score", "", static_cast<std::uint64_t>(runs)});
  return sum;
}

const std::vector<InputInfo> kRadar = {{"radar", "sim.radar", mask(ItemKind::Measurement), {}},
                                       {"truth", "sim.trajectory", mask(ItemKind::Truth), {}}};
// A state with the bias anywhere: the sink finds it by name (InputInfo::state), not by index.
const StateComponent kLayout[13] = {{"x", "m"},  {"vx", "m/s"}, {"vx_prev", "m/s"}, {"y", "m"},  {"vy", "m/s"},
                                    {"vy_prev", "m/s"}, {"z", "m"}, {"vz", "m/s"}, {"vz_prev", "m/s"},
                                    {"range", "m"}, {"azimuth", "rad"}, {"elevation", "rad"}, {"bias", "rad"}};
InputInfo ekf_input(StateLayout layout = {kLayout, 13}) {
  InputInfo in{"ekf", "filter.refraction_ekf", mask(ItemKind::Estimate), {}};
  in.state = layout;
  return in;
}
const std::vector<InputInfo> kEkf = {ekf_input(), {"truth", "sim.trajectory", mask(ItemKind::Truth), {}}};

}  // namespace

// Measurements 0.01 deg high, except 0.05 deg at t = 70 s in run 1: with below 10 deg and from 30
// s, samples t = 30..100 (el 9 -> 2 deg) are scored; max 0.05 deg, RMS over both runs, the mean of
// each run's max 0.03 deg. t < 20 s (el > 10 deg) would carry 1 deg and must not count.
TEST_CASE("errors in degrees per run and ensemble") {
  const Summary s = score("{below: 10 deg, from_time: 30 s}", kRadar, 2, [](Component& c, int run) {
    for (int k = 0; k <= 100; ++k) {
      const double t = k;
      c.on_truth(truth_at(t), 1);
      const double err = t < 20 ? 1.0 : (run == 1 && k == 70 ? 0.05 : 0.01);
      c.on_measurement(measurement_at(t, err * kDeg), 0);
    }
  });
  CHECK(s.find("samples")->value == 2 * 71);
  CHECK(s.find("max_error")->value == Approx(0.05).epsilon(1e-9));
  CHECK(s.find("max_error")->unit == "deg");
  CHECK(s.find("run_max_error_mean")->value == Approx(0.03).epsilon(1e-9));
  CHECK(s.find("rms_error")->value == Approx(std::sqrt((141 * 1e-4 + 25e-4) / 142)).epsilon(1e-9));
  CHECK(s.find("mean_error")->value == Approx((141 * 0.01 + 0.05) / 142).epsilon(1e-9));
  REQUIRE(s.series.size() == 2);
  CHECK(s.series[0].rows() == 2);  // per run
  CHECK(s.series[1].rows() == 71);  // per scored step
}

// score_bias: the refraction EKF's state 12 against Clark's b at the true elevation.
TEST_CASE("bias estimate scored against the true clark bias") {
  sim::ClarkModel clark;
  const Summary s = score("{score_bias: true, refraction: clark, above: 2 deg}", kEkf, 1, [&](Component& c, int) {
    for (int k = 0; k <= 100; ++k) {
      c.on_truth(truth_at(k), 1);
      c.on_estimate(estimate_at(k, 0.0, clark.bias(true_el(k)) + 0.002 * kDeg), 0);
    }
  });
  CHECK(s.find("samples")->value == 100);  // el(100) = 2 deg exactly is not above 2 deg
  CHECK(s.find("bias_rms_error")->value == Approx(0.002).epsilon(1e-6));
  CHECK(s.find("bias_max_error")->value == Approx(0.002).epsilon(1e-6));
  CHECK(s.find("max_error")->value < 1e-9);
}

TEST_CASE("elevation sink wiring and parameters are checked") {
  auto sink = test::make("sink.elevation_error", "{score_bias: true, refraction: clark}");
  CHECK_THROWS_WITH(sink->set_inputs({{"kf", "filter.ekf", mask(ItemKind::Estimate), {}}, kEkf[1]}),
                    Catch::Contains("input 'kf' (filter.ekf) has no state layout"));
  // A layout without a component named "bias", or with one in other units, is refused with what it has.
  CHECK_THROWS_WITH(sink->set_inputs({ekf_input({kLayout, 12}), kEkf[1]}),
                    Catch::Contains("has the state x (m), vx (m/s)") && Catch::Contains("elevation (rad)"));
  const StateComponent metres[1] = {{"bias", "m"}};
  CHECK_THROWS_WITH(sink->set_inputs({ekf_input({metres, 1}), kEkf[1]}), Catch::Contains("bias (m)"));
  auto plain = test::make("sink.elevation_error");
  CHECK_THROWS_WITH(plain->set_inputs({kEkf[0], kEkf[0], kEkf[1]}), Catch::Contains("one filter or one measurement"));
  CHECK_THROWS_WITH(test::make("sink.elevation_error", "score_bias: true"), Catch::Contains("truth's refraction"));
  CHECK_THROWS_WITH(test::make("sink.elevation_error", "refraction: clark"), Catch::Contains("score_bias"));
  CHECK_THROWS_WITH(test::make("sink.elevation_error", "{above: 10 deg, below: 2 deg}"), Catch::Contains("'above'"));
}
