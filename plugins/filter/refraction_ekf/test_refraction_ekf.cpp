// Purpose: tests of filter.refraction_ekf as a plugin: the bias estimate follows a matched Clark bias on a descending pass, normalisation/scaling off still run finite and report convergence, the low-pass noise estimate, the published (unscaled) estimate and the parameter checks.
#include "physics/refraction.hpp"
#include "lpf_noise.hpp"
#include "refraction_ekf_model.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;
namespace rx = trackflow::refraction_ekf;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// A target 600-1050 km north of the radar descending from 100 to 55 km: elevation 9.5 -> 3 deg
// in 150 s; 20 Hz; the radar adds Clark's b (N0 312.5, theta in rad) and 0.001 deg noise.
std::vector<Measurement> descending_pass(std::uint64_t seed, double n0 = 312.5) {
  auto traj = test::make("sim.trajectory",
                         "rate: 20 Hz\ninitial_position: [0, 600 km, 100 km]\ninitial_velocity: [0, 3000, -300]\n"
                         "segments: [{type: constant_velocity, duration: 150 s}]");
  test::Collector truths;
  truths.attach_to(*traj);
  test::drain(*traj);
  auto radar = test::make("sim.radar", "sigma_range: 5 m\nsigma_azimuth: 0.001 deg\nsigma_elevation: 0.001 deg\n"
                                       "refraction: clark\nn0: " + std::to_string(n0));
  test::Collector ms;
  ms.attach_to(*radar);
  Diagnostics d;
  radar->start_run({0, seed, &d});
  for (const Truth& t : truths.truths) radar->on_truth(t, 0);
  return ms.measurements;
}

double true_elevation(double t) {
  const double y = 600e3 + 3000 * t, z = 100e3 - 300 * t;
  return std::atan2(z, y);
}

struct Outcome {
  std::vector<Estimate> estimates;
  Summary summary;
};

Outcome filter(const std::string& yaml, const std::vector<Measurement>& ms) {
  auto f = test::make("filter.refraction_ekf", yaml);
  test::Collector out;
  out.attach_to(*f);
  Diagnostics d;
  testing::start_run(*f, 0, 1, &d);
  for (const Measurement& m : ms) f->on_measurement(m, 0);
  auto r = f->end_run();
  f->merge(*r);
  Outcome o;
  f->finish(o.summary, {});
  o.estimates = std::move(out.estimates);
  return o;
}

double metric(const Summary& s, const char* name) {
  const Metric* m = s.find(name);
  return m ? m->value : NAN;
}

std::string config_error(const std::string& yaml) {
  try {
    (void)test::make("filter.refraction_ekf", yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

// With the filter's N0 equal to the radar's, the estimated bias follows the true b(el) (0.10 -> 0.31
// deg) within 0.001 deg RMS over the last 100 s and the estimated elevation within 0.006 deg, where
// the uncorrected measurement is 0.1-0.3 deg off; the run is reported converged.
TEST_CASE("bias estimate follows a matched clark bias") {
  const auto ms = descending_pass(3);
  const Outcome o = filter("sigma_accel: 20 m/s2", ms);
  sim::ClarkModel clark;
  double sq = 0.0, worst = 0.0;
  int n = 0;
  for (const Estimate& e : o.estimates) {
    if (!e.initialised || e.time < 50.0) continue;
    REQUIRE(e.state.allFinite());
    const double el = true_elevation(e.time);
    const double b_err = e.state(rx::kBias) - clark.bias(el);
    sq += b_err * b_err;
    ++n;
    worst = std::max(worst, std::abs(e.state(rx::kElevation) - el));
    // The published ENU position is the radar states' (range, azimuth, elevation).
    const Vec3 p = spherical_to_enu(e.state(rx::kRange), e.state(rx::kAzimuth), e.state(rx::kElevation),
                                    AzimuthConvention::NorthClockwise);
    CHECK((e.enu.head<3>() - p).norm() < 1e-6);
  }
  REQUIRE(n > 1500);
  INFO("bias RMS error " << std::sqrt(sq / n) / kDeg << " deg, worst elevation error " << worst / kDeg << " deg");
  CHECK(std::sqrt(sq / n) < 0.001 * kDeg);
  CHECK(worst < 0.006 * kDeg);
  CHECK(metric(o.summary, "converged_runs") == 1);
  CHECK(metric(o.summary, "gain_normalised") == metric(o.summary, "updates"));
  // The published covariance is in SI (unscaled): the position variance is in m^2, not 1e-12 m^2.
  CHECK(o.estimates.back().covariance(rx::kX, rx::kX) > 1.0);
}

// Without the bias state the filter tracks the apparent elevation: its error is Clark's b.
TEST_CASE("no bias state leaves b in the elevation") {
  const auto ms = descending_pass(3);
  const Outcome o = filter("sigma_accel: 20 m/s2\nbias_state: false", ms);
  sim::ClarkModel clark;
  const Estimate& e = o.estimates.back();
  const double el = true_elevation(e.time);
  CHECK(e.state(rx::kBias) == 0.0);
  CHECK(e.state(rx::kElevation) - el == Approx(clark.bias(el)).epsilon(0.05));
}

// Paper 004 §2.4: the gain normalisation needs the scaling. Off/off, on/on and off/on run finite
// and converge; normalisation without scaling (K / ||K|| dominated by the metre-per-radian rows)
// leaves the radar states without gain: every estimate is still finite, and the summary says the
// run did not converge.
TEST_CASE("normalisation and scaling off run finite") {
  const auto ms = descending_pass(5);
  struct Case {
    const char* yaml;
    bool converges;
  };
  for (const Case& c : {Case{"gain_normalisation: off\nstate_scale: 1", true},
                        Case{"gain_normalisation: off", true},
                        Case{"gain_normalisation: always\nstate_scale: 1", false},
                        Case{"gain_normalisation: when_large", true}}) {
    INFO(c.yaml);
    const Outcome o = filter(c.yaml, ms);
    for (const Estimate& e : o.estimates) {
      REQUIRE(e.state.allFinite());
      REQUIRE(e.covariance.allFinite());
      REQUIRE(e.enu.allFinite());
    }
    CHECK(metric(o.summary, "converged_runs") == (c.converges ? 1 : 0));
    CHECK(metric(o.summary, "not_converged_runs") == (c.converges ? 0 : 1));
    CHECK(metric(o.summary, "non_finite_steps") == 0);
  }
}

// White noise through the first-order low-pass at 40 Hz and 100 rad/s: the residual keeps
// kappa = 2 (1 - alpha)^2 / (2 - alpha) = 1.2 % of the variance; corrected, the estimate is sigma^2
// within 10 % (20 s windows: ~800 effective samples), also on a ramp of 8 km/s (the lag is taken
// out with the running mean).
TEST_CASE("low-pass residual noise estimate") {
  const double T = 0.025, cutoff = 100.0, sigma = 5.0;
  const double alpha = 1.0 - std::exp(-cutoff * T), kappa = 2 * (1 - alpha) * (1 - alpha) / (2 - alpha);
  Rng rng;
  rng.reseed(11);
  rx::LowPassNoise corrected, raw;
  for (int k = 0; k < 40 * 120; ++k) {
    const double z = 8000.0 * k * T + sigma * rng.normal();
    corrected.add(z, T, cutoff, 20.0, true, false);
    raw.add(z, T, cutoff, 20.0, false, false);
  }
  CHECK(corrected.variance() == Approx(sigma * sigma).epsilon(0.1));
  CHECK(raw.variance() == Approx(kappa * sigma * sigma).epsilon(0.1));
  CHECK(kappa == Approx(0.0124).epsilon(0.01));
}

// measurement_noise: low_pass estimates R itself: the bias is still followed, and no adapter may
// set R (the handle offers none).
TEST_CASE("low-pass measurement noise runs and hides R") {
  const auto ms = descending_pass(4);
  const Outcome o = filter("sigma_accel: 20 m/s2\nmeasurement_noise: low_pass", ms);
  sim::ClarkModel clark;
  const Estimate& e = o.estimates.back();
  CHECK(std::abs(e.state(rx::kBias) - clark.bias(true_elevation(e.time))) < 0.01 * kDeg);
  auto f = std::dynamic_pointer_cast<Filter>(test::make("filter.refraction_ekf", "measurement_noise: low_pass"));
  CHECK_FALSE(f->noise().measurement);
  auto g = std::dynamic_pointer_cast<Filter>(test::make("filter.refraction_ekf"));
  CHECK(g->noise().measurement.space == MeasurementSpace::Spherical);
  CHECK(g->noise().process.count == 3);
  CHECK(g->noise().process.kind == NoiseKind::StandardDeviation);
  CHECK(g->state_layout().dim == 13);
  CHECK(std::string(g->state_layout().components[rx::kBias].name) == "bias");
}

TEST_CASE("refraction ekf parameters are checked") {
  CHECK_THAT(config_error("gain_normalisation: off\ngain_lambda: 0.5"), Catch::Matchers::Contains("'gain_lambda'"));
  CHECK_THAT(config_error("lpf_cutoff: 50 rad/s"), Catch::Matchers::Contains("measurement_noise: low_pass"));
  CHECK_THAT(config_error("bias_state: false\nq_bias: 1e-10 rad2/s"), Catch::Matchers::Contains("'q_bias'"));
  CHECK_THAT(config_error("clark_coefficients: [0.1, 1, 0, 0]"), Catch::Matchers::Contains("beta1"));
  CHECK(config_error("n0: 343.75\nclark_theta_unit: deg").empty());
}
