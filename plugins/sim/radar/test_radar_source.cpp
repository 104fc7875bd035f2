// Purpose: tests of sim.radar: exact geometry at zero noise, noise and bias statistics, seeding, azimuth wrap, degenerate geometry.
#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

constexpr double kPi = std::numbers::pi;

Truth truth_at(double t, const Vec3& p, const Vec3& v = Vec3::Zero()) {
  Truth x;
  x.time = t;
  x.position = p;
  x.velocity = v;
  return x;
}

// One run of a radar over `truths`.
std::vector<Measurement> measure(const std::string& yaml, const std::vector<Truth>& truths, std::uint64_t seed = 1,
                                 Diagnostics* diag = nullptr) {
  auto radar = test::make("sim.radar", yaml);
  test::Collector out;
  out.attach_to(*radar);
  Diagnostics local;
  radar->start_run({0, seed, diag ? diag : &local});
  for (const Truth& t : truths) radar->on_truth(t, 0);
  return out.measurements;
}

struct Moments {
  double mean = 0.0, sd = 0.0;
};
Moments moments(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  const double mean = s / x.size();
  double ss = 0.0;
  for (double v : x) ss += (v - mean) * (v - mean);
  return {mean, std::sqrt(ss / (x.size() - 1))};
}
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const Moments ma = moments(a), mb = moments(b);
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) s += (a[i] - ma.mean) * (b[i] - mb.mean);
  return s / (a.size() - 1) / (ma.sd * mb.sd);
}

const char* kNoNoise = "sigma_range: 0 m\nsigma_azimuth: 0 rad\nsigma_elevation: 0 rad\nsigma_range_rate: 0 m/s\n";

}  // namespace

// without noise the measurement is the exact geometry, for both conventions and an offset sensor
TEST_CASE("without noise the measurement is exact geometry") {
  const Vec3 sensor(1000, -2000, 30);
  const std::vector<Truth> truths = {
      truth_at(0.0, sensor + Vec3(5000, 0, 0), Vec3(10, 0, 0)),                 // due east, level
      truth_at(0.5, sensor + Vec3(0, 8000, 0), Vec3(3, -4, 1)),                 // due north
      truth_at(1.0, sensor + Vec3(-3000, -3000, 3000 * std::sqrt(2.0))),        // south-west, 45 deg up
      truth_at(1.5, sensor + Vec3(12345, -6789, 2500), Vec3(-150, 220, 35)),    // generic
  };
  for (const char* conv : {"north_clockwise", "x_counterclockwise"}) {
    INFO(conv);
    const bool nc = std::string(conv) == "north_clockwise";
    const auto c = nc ? AzimuthConvention::NorthClockwise : AzimuthConvention::XCounterClockwise;
    const auto ms = measure(std::string(kNoNoise) + "position: [1 km, -2 km, 30 m]\nrange_rate: true\nsensor_id: 4\n" +
                                "azimuth_convention: " + conv,
                            truths);
    REQUIRE(ms.size() == truths.size());
    for (size_t i = 0; i < ms.size(); ++i) {
      const Measurement& m = ms[i];
      const Vec3 d = truths[i].position - sensor;
      CHECK(m.time == truths[i].time);
      CHECK(m.sensor == 4u);
      CHECK(m.frame == Frame::Spherical);
      CHECK(m.azimuth == c);
      CHECK(m.mode == MeasMode::Unknown);
      CHECK(m.valid);
      CHECK(m.has_range_rate);
      CHECK((m.sensor_position - sensor).norm() == 0.0);
      REQUIRE(m.value.size() == 4);
      CHECK(m.value(0) == Approx(d.norm()).epsilon(1e-14));
      // Back to ENU with the convention's own formula lands on the target.
      CHECK((spherical_to_enu(m.value(0), m.value(1), m.value(2), c) + sensor - truths[i].position).norm() < 1e-8);
      // Range rate against a central difference of the range along the relative velocity.
      const double h = 1e-3;
      const double fd = ((d + h * truths[i].velocity).norm() - (d - h * truths[i].velocity).norm()) / (2 * h);
      CHECK(m.value(3) == Approx(fd).margin(1e-7));
      CHECK(m.covariance.isZero());
    }
    CHECK(ms[0].value(1) == Approx(nc ? kPi / 2 : 0.0).margin(1e-15));
    CHECK(ms[1].value(1) == Approx(nc ? 0.0 : kPi / 2).margin(1e-15));
    CHECK(ms[2].value(1) == Approx(-3 * kPi / 4).margin(1e-15));  // the diagonal is symmetric in both
    CHECK(ms[2].value(2) == Approx(kPi / 4));
    CHECK(ms[0].value(2) == 0.0);
  }
}

// range rate is off by default: a 3-element value and 3x3 covariance diag(sigma^2)
TEST_CASE("range rate is off by default") {
  const auto ms = measure("sigma_range: 7 m\nsigma_azimuth: 2 mrad\nsigma_elevation: 0.5 mrad",
                          {truth_at(0, Vec3(1000, 2000, 300))});
  REQUIRE(ms.size() == 1);
  REQUIRE(ms[0].value.size() == 3);
  CHECK_FALSE(ms[0].has_range_rate);
  REQUIRE(ms[0].covariance.rows() == 3);
  REQUIRE(ms[0].covariance.cols() == 3);
  CHECK(ms[0].covariance(0, 0) == Approx(49.0));
  CHECK(ms[0].covariance(1, 1) == Approx(4e-6));
  CHECK(ms[0].covariance(2, 2) == Approx(0.25e-6));
  CHECK(ms[0].covariance(0, 1) == 0.0);
  CHECK(ms[0].covariance(1, 2) == 0.0);
}

// errors have the configured bias as mean and sigma as spread - channels are independent
TEST_CASE("errors have the configured bias and sigma") {
  const double sr = 10.0, saz = 2e-3, sel = 1.5e-3, srr = 0.5;
  const double br = 5.0, baz = -3e-3, bel = 2e-3;
  const Vec3 sensor(100, 200, 10), p(-4000, 7000, 1500), v(120, -30, 8);
  const int n = 40000;
  std::vector<Truth> truths;
  for (int k = 0; k < n; ++k) truths.push_back(truth_at(0.025 * k, p, v));
  const auto ms = measure("position: [100, 200, 10]\nsigma_range: 10 m\nsigma_azimuth: 2 mrad\nsigma_elevation: 1.5 mrad\n"
                          "range_rate: true\nsigma_range_rate: 0.5 m/s\n"
                          "bias_range: 5 m\nbias_azimuth: -3 mrad\nbias_elevation: 2 mrad",
                          truths, 20240607);
  REQUIRE(ms.size() == static_cast<size_t>(n));
  // Exact values computed here, independently of the plugin: compass azimuth atan2(east, north).
  const Vec3 d = p - sensor;
  const double r = d.norm(), az = std::atan2(d.x(), d.y()), el = std::asin(d.z() / r), rr = d.dot(v) / r;
  std::vector<double> er, eaz, eel, err;
  for (const auto& m : ms) {
    er.push_back(m.value(0) - r);
    eaz.push_back(wrap_angle(m.value(1) - az));
    eel.push_back(m.value(2) - el);
    err.push_back(m.value(3) - rr);
    CHECK(m.covariance.diagonal().isApprox(Eigen::Vector4d(sr * sr, saz * saz, sel * sel, srr * srr)));
  }
  const double root_n = std::sqrt(static_cast<double>(n));
  struct Channel {
    const char* name;
    const std::vector<double>& e;
    double bias, sigma;
  };
  for (const Channel& c : {Channel{"range", er, br, sr}, Channel{"azimuth", eaz, baz, saz},
                           Channel{"elevation", eel, bel, sel}, Channel{"range rate", err, 0.0, srr}}) {
    INFO(c.name);
    const Moments mo = moments(c.e);
    CHECK(std::abs(mo.mean - c.bias) < 4 * c.sigma / root_n);
    // Standard error of a sample sd is sigma / sqrt(2n) (0.35 % here); 3 % is far outside chance.
    CHECK(mo.sd == Approx(c.sigma).epsilon(0.03));
  }
  // Independent draws: correlations within 4 standard errors (1/sqrt(n)) of zero.
  CHECK(std::abs(correlation(er, eaz)) < 4 / root_n);
  CHECK(std::abs(correlation(eaz, eel)) < 4 / root_n);
  CHECK(std::abs(correlation(eel, err)) < 4 / root_n);
}

// the same seed gives identical measurements, another seed different ones
TEST_CASE("the same seed gives identical measurements") {
  std::vector<Truth> truths;
  for (int k = 0; k < 50; ++k) truths.push_back(truth_at(0.1 * k, Vec3(3000 + 10 * k, 4000, 500), Vec3(100, 0, 0)));
  const std::string yaml = "range_rate: true";
  const auto a = measure(yaml, truths, 77), b = measure(yaml, truths, 77), c = measure(yaml, truths, 78);
  REQUIRE(a.size() == truths.size());
  int differing = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].value == b[i].value);
    if (a[i].value(0) != c[i].value(0) && a[i].value(1) != c[i].value(1)) ++differing;
  }
  CHECK(differing == static_cast<int>(a.size()));

  // start_run reseeds: a second run with the same seed on the same instance repeats the first.
  auto radar = test::make("sim.radar", yaml);
  test::Collector out;
  out.attach_to(*radar);
  Diagnostics diag;
  for (int run = 0; run < 2; ++run) {
    radar->start_run({static_cast<std::uint64_t>(run), 77, &diag});
    for (const Truth& t : truths) radar->on_truth(t, 0);
  }
  REQUIRE(out.measurements.size() == 2 * truths.size());
  for (size_t i = 0; i < truths.size(); ++i) CHECK(out.measurements[i].value == out.measurements[i + truths.size()].value);
}

TEST_CASE("measured azimuth is wrapped into -pi < az <= pi") {
  SECTION("a target due south (north_clockwise) is at +pi exactly without noise") {
    const auto ms = measure(kNoNoise, {truth_at(0, Vec3(0, -5000, 0))});
    CHECK(ms.at(0).value(1) == kPi);
  }
  SECTION("a target due west (x_counterclockwise) is at +pi exactly without noise") {
    const auto ms = measure(std::string(kNoNoise) + "azimuth_convention: x_counterclockwise", {truth_at(0, Vec3(-5000, 0, 0))});
    CHECK(ms.at(0).value(1) == kPi);
  }
  SECTION("noise around due south lands on both sides of the cut, never outside (-pi, pi]") {
    const int n = 20000;
    const std::vector<Truth> truths(n, truth_at(0, Vec3(0, -5000, 100)));
    const auto ms = measure("sigma_azimuth: 50 mrad", truths, 5);
    int negative = 0;
    std::vector<double> err;
    for (const auto& m : ms) {
      const double az = m.value(1);
      CHECK((az > -kPi && az <= kPi));
      if (az < 0) ++negative;
      err.push_back(wrap_angle(az - kPi));
    }
    CHECK(negative > n / 3);
    CHECK(negative < 2 * n / 3);
    const Moments mo = moments(err);
    CHECK(std::abs(mo.mean) < 4 * 0.05 / std::sqrt(static_cast<double>(n)));
    CHECK(mo.sd == Approx(0.05).epsilon(0.03));
  }
  SECTION("a bias that pushes past pi wraps too") {
    const auto ms = measure(std::string(kNoNoise) + "bias_azimuth: 0.5 rad", {truth_at(0, Vec3(std::sin(3.0), std::cos(3.0), 0) * 1e4)});
    CHECK(ms.at(0).value(1) == Approx(3.5 - 2 * kPi));
  }
}

// a target at the radar or straight overhead gives finite values
TEST_CASE("a target at the radar or overhead is finite") {
  const std::vector<Truth> truths = {
      truth_at(0, Vec3(50, 60, 70), Vec3(10, -20, 5)),      // at the sensor
      truth_at(1, Vec3(50, 60, 70), Vec3::Zero()),          // at the sensor, still
      truth_at(2, Vec3(50, 60, 5070), Vec3(0, 0, -100)),    // zenith
      truth_at(3, Vec3(50, 60, 5070), Vec3(30, 40, 0)),     // zenith, moving across
  };
  for (const char* conv : {"north_clockwise", "x_counterclockwise"}) {
    const std::string params = std::string("position: [50, 60, 70]\nrange_rate: true\nazimuth_convention: ") + conv;
    for (const auto& ms : {measure(params, truths), measure(std::string(kNoNoise) + params, truths)}) {
      REQUIRE(ms.size() == truths.size());
      for (const auto& m : ms) {
        CHECK(m.value.allFinite());
        CHECK(m.covariance.allFinite());
      }
    }
    const auto exact = measure(std::string(kNoNoise) + params, truths);
    CHECK(exact[0].value(0) == 0.0);
    CHECK(exact[0].value(3) == Approx(Vec3(10, -20, 5).norm()));
    CHECK(exact[2].value(0) == Approx(5000));
    CHECK(exact[2].value(2) == Approx(kPi / 2));
    CHECK(exact[2].value(3) == Approx(-100));
    CHECK(exact[3].value(3) == 0.0);
  }
}

// 'every: 3' keeps one truth item in three, counting afresh each run
TEST_CASE("every: 3 keeps one truth item in three per run") {
  std::vector<Truth> truths;
  for (int k = 0; k < 10; ++k) truths.push_back(truth_at(k, Vec3(1000, 1000, 100)));
  const auto ms = measure("every: 3", truths);
  REQUIRE(ms.size() == 4);
  for (size_t i = 0; i < ms.size(); ++i) CHECK(ms[i].time == 3.0 * i);

  auto radar = test::make("sim.radar", "every: 3");
  test::Collector out;
  out.attach_to(*radar);
  Diagnostics diag;
  for (int run = 0; run < 2; ++run) {
    radar->start_run({static_cast<std::uint64_t>(run), 1, &diag});
    for (int k = 0; k < 5; ++k) radar->on_truth(truths[k], 0);
  }
  REQUIRE(out.measurements.size() == 4);  // items 0 and 3 of each run
  CHECK(out.measurements[2].time == 0.0);
}

// a non-finite truth is skipped with a diagnostic, not turned into NaN
TEST_CASE("a non-finite truth is skipped with a diagnostic") {
  Diagnostics diag;
  Truth bad = truth_at(1, Vec3(1000, std::nan(""), 0));
  const auto ms = measure("{}", {truth_at(0, Vec3(1000, 0, 0)), bad, truth_at(2, Vec3(1000, 0, 0))}, 1, &diag);
  REQUIRE(ms.size() == 2);
  REQUIRE(diag.skips.size() == 1);
  CHECK(diag.skips[0].node == "node");
}

TEST_CASE("bad radar parameters are refused") {
  auto fails = [](const std::string& yaml, const std::string& name) {
    try {
      (void)test::make("sim.radar", yaml);
    } catch (const ConfigError& e) {
      return std::string(e.what()).find(name) != std::string::npos;
    }
    return false;
  };
  CHECK(fails("sigma_range: -1 m", "sigma_range"));
  CHECK(fails("sigma_azimuth: 3 m", "sigma_azimuth"));
  CHECK(fails("every: 0", "every"));
  CHECK(fails("position: [1, 2]", "position"));
  CHECK(fails("azimuth_convention: south", "azimuth_convention"));
}
