// Purpose: tests of several radars into one filter (filter.ekf and filter.ukf through the shared front end): per-sensor NIS in the summary, a tilted sensor's own axes, an unmodelled station bias singled out.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <cmath>

#include "plugin_fixture.hpp"
#include "estimation/radar_filter_test_support.hpp"

using namespace trackflow;
using namespace trackflow::filter_test;

namespace {

// A sensor 60 km east whose horizon is tilted 0.6 deg about the north axis (its up leans east),
// as a site 0.6 deg of arc away would be.
const Vec3 kSiteB(60e3, 0.0, 0.0);
Mat3 tilted_axes() { return Eigen::AngleAxisd(0.6 * std::numbers::pi / 180, Vec3::UnitY()).toRotationMatrix(); }

// Measurement of sensor B from its own axes: r, az, el of A' (p - s), elevation biased by `bias`.
Measurement tilted(double t, const Vec3& p, double bias, Rng& rng) {
  const RadarNoise noise{5.0, 0.5e-3, 0.5e-3};
  const Mat3 A = tilted_axes();
  Measurement m = radar(t, A.transpose() * (p - kSiteB), Vec3::Zero(), Vec3::Zero(), noise, &rng, false);
  m.value(2) += bias;
  m.sensor_position = kSiteB;
  m.sensor_axes = A;
  m.sensor_level = false;
  return m;
}

// 20 runs of a constant-velocity target seen by a level radar A at the origin (10 Hz) and the
// tilted radar B (5 Hz, at A's even time stamps, delivered after A's): the filter's summary.
Summary two_sensor_summary(const std::string& type, double bias_b) {
  auto f = test::make(type, "{q: 1e-4 m2/s3}", "fused");
  f->set_inputs({{"a", "sim.radar", mask(ItemKind::Measurement), {}}, {"b", "sim.radar", mask(ItemKind::Measurement), {}}});
  test::Collector out;
  out.attach_to(*f);
  Rng rng(11);
  const RadarNoise noise_a{10.0, 1e-3, 1e-3};
  for (int run = 0; run < 20; ++run) {
    Diagnostics diag;
    f->start_run({static_cast<std::uint64_t>(run), 1, &diag});
    const Vec3 p0(20e3, 40e3, 8e3), v(-120.0, 60.0, 5.0);
    for (int k = 0; k < 600; ++k) {
      const double t = 0.1 * k;
      const Vec3 p = p0 + t * v;
      f->on_measurement(radar(t, p, v, Vec3::Zero(), noise_a, &rng, false), 0);
      if (k % 2 == 0) f->on_measurement(tilted(t, p, bias_b, rng), 1);
    }
    auto r = f->end_run();
    f->merge(*r);
  }
  Summary s;
  f->finish(s, {});
  return s;
}

void check_consistent(const Metric* m) {
  REQUIRE(m != nullptr);
  REQUIRE(m->has_band);
  CHECK(m->value >= m->band_lo);
  CHECK(m->value <= m->band_hi);
}

}  // namespace

// Both stations described correctly: each one's mean NIS inside its 95 % band, and the updates
// counted per station (600 + 300 per run, less the two-point initialisation's). Ignoring B's
// tilt (0.6 deg = 10 mrad against 0.5 mrad of noise) would put its NIS in the hundreds.
TEST_CASE("ekf: several radars - NIS per sensor in band and tilt") {
  for (const char* type : {"filter.ekf", "filter.ukf"}) {
    INFO(type);
    const Summary s = two_sensor_summary(type, 0.0);
    check_consistent(s.find("nis_mean.a"));
    check_consistent(s.find("nis_mean.b"));
    REQUIRE(s.find("updates.a") != nullptr);
    CHECK(s.find("updates.a")->value == Approx(20 * 599).margin(40));
    CHECK(s.find("updates.b")->value == Approx(20 * 300).margin(40));
  }
}

// An elevation bias of 1.5 mrad (3 sigma) on station B that the filter does not know: B's mean
// NIS leaves its band and stands above A's (A's rises too: the track is pulled towards B).
TEST_CASE("ekf: several radars - unmodelled bias shows in its NIS") {
  const Summary s = two_sensor_summary("filter.ekf", 1.5e-3);
  const Metric* b = s.find("nis_mean.b");
  const Metric* a = s.find("nis_mean.a");
  REQUIRE(b != nullptr);
  REQUIRE(a != nullptr);
  CHECK(b->value > b->band_hi);
  CHECK(b->value > a->value + 0.2);
}

// A single-input filter keeps its summary as before: no per-sensor entries.
TEST_CASE("ekf: one radar - no per-sensor entries in the summary") {
  auto f = test::make("filter.ekf", "{q: 0.01 m2/s3}", "one");
  f->set_inputs({{"a", "sim.radar", mask(ItemKind::Measurement), {}}});
  Diagnostics diag;
  f->start_run({0, 1, &diag});
  Rng rng(3);
  for (int k = 0; k < 10; ++k)
    f->on_measurement(radar(0.1 * k, Vec3(1e4, 2e4, 1e3), Vec3::Zero(), Vec3::Zero(), RadarNoise{}, &rng, false), 0);
  auto r = f->end_run();
  f->merge(*r);
  Summary s;
  f->finish(s, {});
  CHECK(s.find("nis_mean.a") == nullptr);
  CHECK(s.find("updates.a") == nullptr);
}
