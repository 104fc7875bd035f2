// Purpose: tests of sim.scan_radar: one look per instant, coverage, P_D models against their definitions and a Monte Carlo detector, clutter rate and spread, merged plots, determinism, refusals.
#include <catch2/catch.hpp>

#include "detection_models.hpp"
#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Look {
  Frame frame = Frame::Spherical;
  double time = 0.0;
  std::vector<Detection> detections;
  SurveillanceRegion region;
  double clutter_density = 0.0, pd = 0.0;
};

class Recorder final : public Component {
 public:
  void on_scan(const Scan& s, int) override {
    looks.push_back({s.sensor.frame, s.time, {s.detections.begin(), s.detections.end()}, s.region, s.clutter_density,
                     s.detection_probability});
  }
  std::vector<Look> looks;
};

struct Radar {
  std::shared_ptr<Component> node;
  Recorder rec;
  Link link{&rec, 0, 0xFF};
  explicit Radar(const std::string& yaml, std::uint64_t seed = 1) : node(test::make("sim.scan_radar", yaml)) {
    node->out.connect(&link, 1);
    test::start_run(*node, 0, seed);
  }
  void truth(double t, std::uint32_t id, const Vec3& p) {
    Truth x;
    x.time = t;
    x.target = id;
    x.position = p;
    node->on_truth(x, 0);
  }
};

std::string refusal(const std::string& yaml) {
  try {
    (void)test::make("sim.scan_radar", yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

Vec3 at(double r, double az, double el) { return spherical_to_enu(r, az, el, AzimuthConvention::NorthClockwise); }

}  // namespace

TEST_CASE("one scan per instant with every target of it", "[scan_radar]") {
  Radar radar("range_max: 100 km\nsigma_range: 0 m\nsigma_azimuth: 0 rad\nsigma_elevation: 0 rad\n");
  radar.truth(1.0, 3, at(10e3, 0.5, 0.1));
  radar.truth(1.0, 1, at(20e3, -0.5, 0.2));
  REQUIRE(radar.rec.looks.empty());  // nothing until the instant is closed
  radar.node->on_time_complete(1.0);
  radar.truth(2.0, 1, at(21e3, -0.5, 0.2));
  radar.node->on_time_complete(2.0);
  radar.node->on_time_complete(3.0);  // an instant without truth: no look
  REQUIRE(radar.rec.looks.size() == 2);
  const Look& a = radar.rec.looks[0];
  CHECK(a.time == 1.0);
  REQUIRE(a.detections.size() == 2);
  // Sorted by range: target 3 (10 km) first; noiseless values are the geometry.
  CHECK(a.detections[0].origin == 3);
  CHECK(a.detections[0].value[0] == Approx(10e3));
  CHECK(a.detections[0].value[1] == Approx(0.5));
  CHECK(a.detections[1].origin == 1);
  CHECK(a.detections[1].value[2] == Approx(0.2));
  CHECK(a.pd == 1.0);
  CHECK(a.region.known);
  CHECK(a.region.hi[0] == 100e3);
  REQUIRE(radar.rec.looks[1].detections.size() == 1);
  CHECK(radar.rec.looks[1].detections[0].value[0] == Approx(21e3));
}

TEST_CASE("targets outside the coverage are not seen", "[scan_radar]") {
  Radar radar("range_min: 1 km\nrange_max: 50 km\nazimuth_min: 170 deg\nazimuth_max: 200 deg\n"
              "elevation_min: 1 deg\nelevation_max: 30 deg\n");
  radar.truth(0.0, 0, at(10e3, 180 * kDeg, 5 * kDeg));   // in (azimuth interval passes 180 deg)
  radar.truth(0.0, 1, at(10e3, -165 * kDeg, 5 * kDeg));  // 195 deg: in
  radar.truth(0.0, 2, at(10e3, 165 * kDeg, 5 * kDeg));   // azimuth out
  radar.truth(0.0, 3, at(60e3, 180 * kDeg, 5 * kDeg));   // range out
  radar.truth(0.0, 4, at(0.5e3, 180 * kDeg, 5 * kDeg));  // too near
  radar.truth(0.0, 5, at(10e3, 180 * kDeg, 40 * kDeg));  // elevation out
  radar.node->on_time_complete(0.0);
  REQUIRE(radar.rec.looks.size() == 1);
  std::vector<std::uint32_t> seen;
  for (const auto& d : radar.rec.looks[0].detections) seen.push_back(d.origin);
  std::sort(seen.begin(), seen.end());
  CHECK(seen == std::vector<std::uint32_t>{0, 1});
}

TEST_CASE("Swerling P_D matches a simulated square-law detector", "[scan_radar]") {
  // Complex Gaussian noise of unit power per sample; the threshold gives P_FA on noise alone.
  Rng rng(7);
  const double pfa = 1e-2, threshold = -std::log(pfa);  // |n|^2 ~ Exp(1): P(|n|^2 > T) = e^-T
  for (double snr_db : {3.0, 10.0, 13.0}) {
    const double snr = std::pow(10.0, snr_db / 10.0);
    const int n = 200000;
    int steady = 0, fluctuating = 0;
    for (int k = 0; k < n; ++k) {
      const double nr = rng.normal() * std::sqrt(0.5), ni = rng.normal() * std::sqrt(0.5);
      // Steady echo of power snr; Swerling I: its complex amplitude is Gaussian with that mean power.
      const double a = std::sqrt(snr);
      if ((a + nr) * (a + nr) + ni * ni > threshold) ++steady;
      const double fr = rng.normal() * std::sqrt(0.5 * snr), fi = rng.normal() * std::sqrt(0.5 * snr);
      if ((fr + nr) * (fr + nr) + (fi + ni) * (fi + ni) > threshold) ++fluctuating;
    }
    const double tol = 4.0 * std::sqrt(0.25 / n);
    CHECK(static_cast<double>(steady) / n == Approx(scan_radar::pd_swerling0(snr, pfa)).margin(tol));
    CHECK(static_cast<double>(fluctuating) / n == Approx(scan_radar::pd_swerling1(snr, pfa)).margin(tol));
  }
  // Limits: no signal gives P_FA; the steady target is easier to detect at high SNR.
  CHECK(scan_radar::pd_swerling0(0.0, 1e-6) == Approx(1e-6));
  CHECK(scan_radar::pd_swerling1(0.0, 1e-6) == Approx(1e-6));
  CHECK(scan_radar::pd_swerling0(100.0, 1e-6) > scan_radar::pd_swerling1(100.0, 1e-6));
  // SNR law: 40 dB per decade of range.
  CHECK(10.0 * std::log10(scan_radar::snr_at_range(1000e3, 20.0, 100e3)) == Approx(-20.0));
}

TEST_CASE("detections follow P_D and clutter its mean and region", "[scan_radar]") {
  Radar radar("range_min: 10 km\nrange_max: 20 km\nazimuth_min: 0 deg\nazimuth_max: 90 deg\n"
              "elevation_min: 0 deg\nelevation_max: 10 deg\ndetection_probability: 0.7\nclutter_rate: 5\n");
  const int looks = 4000;
  for (int k = 0; k < looks; ++k) {
    radar.truth(k, 0, at(15e3, 45 * kDeg, 5 * kDeg));
    radar.node->on_time_complete(k);
  }
  int hits = 0, clutter = 0;
  double mean_r = 0.0;
  for (const auto& l : radar.rec.looks)
    for (const auto& d : l.detections) {
      if (d.origin == 0) {
        ++hits;
        continue;
      }
      CHECK(d.origin == kOriginClutter);
      ++clutter;
      mean_r += d.value[0];
      CHECK(d.value[0] >= 10e3);
      CHECK(d.value[0] <= 20e3);
      CHECK(d.value[1] >= 0.0);
      CHECK(d.value[1] <= 90 * kDeg);
    }
  CHECK(static_cast<double>(hits) / looks == Approx(0.7).margin(4.0 * std::sqrt(0.21 / looks)));
  CHECK(static_cast<double>(clutter) / looks == Approx(5.0).margin(4.0 * std::sqrt(5.0 / looks)));
  CHECK(mean_r / clutter == Approx(15e3).margin(100.0));
  const double volume = 10e3 * (90 * kDeg) * (10 * kDeg);
  CHECK(radar.rec.looks[0].clutter_density == Approx(5.0 / volume));
}

TEST_CASE("Swerling clutter defaults to P_FA times the cells", "[scan_radar]") {
  Radar radar("range_min: 0 m\nrange_max: 15 km\nazimuth_min: 0 deg\nazimuth_max: 10 deg\nelevation_min: 0 deg\n"
              "elevation_max: 1 deg\nrange_resolution: 15 m\nbeamwidth_azimuth: 1 deg\nbeamwidth_elevation: 1 deg\n"
              "detection_model: swerling1\nfalse_alarm_probability: 1e-3\n");
  // 1000 range cells x 10 x 1 = 1e4 cells: 10 false alarms per look.
  radar.truth(0.0, 0, at(1e9, 0.0, 0.0));  // out of coverage: the look still happens
  radar.node->on_time_complete(0.0);
  REQUIRE(radar.rec.looks.size() == 1);
  CHECK(std::isnan(radar.rec.looks[0].pd));
  const double volume = 15e3 * (10 * kDeg) * (1 * kDeg);
  CHECK(radar.rec.looks[0].clutter_density * volume == Approx(10.0));
}

TEST_CASE("targets in one resolution cell give one plot", "[scan_radar]") {
  const std::string yaml = "range_max: 100 km\nsigma_range: 0 m\nsigma_azimuth: 0 rad\nsigma_elevation: 0 rad\n"
                           "range_resolution: 50 m\nbeamwidth_azimuth: 1 deg\nbeamwidth_elevation: 1 deg\n";
  Radar merged(yaml + "merge_unresolved: true\n"), apart(yaml);
  for (Radar* r : {&merged, &apart}) {
    r->truth(0.0, 4, at(10000.0, 0.1, 0.1));
    r->truth(0.0, 2, at(10040.0, 0.1 + 0.5 * kDeg, 0.1));
    r->truth(0.0, 9, at(10200.0, 0.1, 0.1));  // 200 m beyond: resolved
    r->node->on_time_complete(0.0);
  }
  REQUIRE(apart.rec.looks[0].detections.size() == 3);
  const auto& d = merged.rec.looks[0].detections;
  REQUIRE(d.size() == 2);
  CHECK(d[0].origin == 2);  // the lower id labels the plot
  CHECK(d[0].value[0] == Approx(10020.0));
  CHECK(d[0].value[1] == Approx(0.1 + 0.25 * kDeg));
  CHECK(d[1].origin == 9);
}

TEST_CASE("same seed same scans and another seed other scans", "[scan_radar]") {
  auto run = [](std::uint64_t seed) {
    Radar r("range_max: 50 km\ndetection_probability: 0.8\nclutter_rate: 3\n", seed);
    for (int k = 0; k < 50; ++k) {
      r.truth(k, 0, at(20e3, 0.3, 0.2));
      r.truth(k, 1, at(30e3, -0.3, 0.1));
      r.node->on_time_complete(k);
    }
    std::vector<double> v;
    for (const auto& l : r.rec.looks)
      for (const auto& d : l.detections) v.push_back(d.value[0]);
    return v;
  };
  CHECK(run(5) == run(5));
  CHECK(run(5) != run(6));
}

TEST_CASE("refuses contradictory or impossible parameters", "[scan_radar]") {
  CHECK_THAT(refusal("range_max: 10 km\nrange_min: 20 km\n"), Catch::Contains("above range_min"));
  CHECK_THAT(refusal("range_max: 10 km\nazimuth_min: 10 deg\nazimuth_max: 5 deg\n"), Catch::Contains("above azimuth_min"));
  CHECK_THAT(refusal("range_max: 10 km\nazimuth_min: 200 deg\nazimuth_max: 210 deg\n"), Catch::Contains("[-180 deg, 180 deg]"));
  CHECK_THAT(refusal("range_max: 10 km\ndetection_model: swerling1\ndetection_probability: 0.9\n"),
             Catch::Contains("P_D follows from the SNR"));
  CHECK_THAT(refusal("range_max: 10 km\nfalse_alarm_probability: 1e-4\n"), Catch::Contains("detection_model: swerling0"));
  CHECK_THAT(refusal("range_max: 10 km\nclutter_rate: 3\nclutter_density: 1e-6\n"), Catch::Contains("not both"));
  CHECK_THAT(refusal("range_max: 1000 km\nclutter_density: 10\n"), Catch::Contains("1e7"));
  CHECK_THAT(refusal("sigma_range: 1 m\n"), Catch::Contains("range_max"));
}

// measures: range_azimuth — a 2-D surveillance radar: polar [r, az] plots with a 2x2 covariance,
// clutter over range-azimuth (density per m rad), the fan beam's elevation coverage still applies,
// and merging ignores elevation.
TEST_CASE("2-D radar gives polar range-azimuth plots", "[scan_radar]") {
  Radar radar("measures: range_azimuth\nrange_min: 10 km\nrange_max: 20 km\nazimuth_min: 0 deg\n"
              "azimuth_max: 90 deg\nelevation_max: 10 deg\nsigma_range: 5 m\nsigma_azimuth: 2 mrad\n"
              "detection_probability: 1\nclutter_rate: 3\nmerge_unresolved: true\nbeamwidth_azimuth: 1 deg\n"
              "range_resolution: 50 m\n");
  const int looks = 3000;
  for (int k = 0; k < looks; ++k) {
    radar.truth(k, 0, at(15e3, 45 * kDeg, 2 * kDeg));
    radar.truth(k, 1, at(15e3 + 20, 45.2 * kDeg, 8 * kDeg));  // one (r, az) cell, elevations apart
    radar.truth(k, 2, at(12e3, 30 * kDeg, 20 * kDeg));        // above the fan beam
    radar.node->on_time_complete(k);
  }
  REQUIRE(radar.rec.looks.size() == static_cast<size_t>(looks));
  int clutter = 0, plots = 0;
  for (const auto& l : radar.rec.looks) {
    CHECK(l.frame == Frame::Polar);
    CHECK(l.region.dim == 2);
    for (const auto& d : l.detections) {
      REQUIRE(d.value.size() == 2);
      REQUIRE(d.covariance.rows() == 2);
      CHECK(d.covariance(1, 1) == Approx(4e-6));
      if (d.origin == kOriginClutter) {
        ++clutter;
        CHECK(d.value[0] >= 10e3);
        CHECK(d.value[0] <= 20e3);
      } else {
        CHECK(d.origin == 0);  // target 1 merged into 0; target 2 out of the beam
        ++plots;
      }
    }
  }
  CHECK(plots == looks);
  CHECK(static_cast<double>(clutter) / looks == Approx(3.0).margin(4.0 * std::sqrt(3.0 / looks)));
  CHECK(radar.rec.looks[0].clutter_density == Approx(3.0 / (10e3 * 90 * kDeg)));
  CHECK_THAT(refusal("measures: range_azimuth\nrange_max: 10 km\nsigma_elevation: 1 mrad\n"),
             Catch::Contains("sigma_elevation") && Catch::Contains("no elevation"));
}
