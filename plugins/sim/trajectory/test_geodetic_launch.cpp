// Purpose: tests of the geodetic sites and the WGS-84 launch path: geodetic <-> ECEF <-> ENU round trip, geodesic downrange and ellipsoidal altitude at the table rows, derivatives, parameter checks.
#include "physics/geodesy.hpp"
#include "geodetic_launch.hpp"
#include "launch_profile.hpp"

#include <GeographicLib/Geodesic.hpp>
#include <catch2/catch.hpp>

#include "trajectory_test_support.hpp"

#include <cmath>
#include <numbers>
#include <string>

using namespace trackflow;

namespace {

constexpr double kDeg = std::numbers::pi / 180;
const sim::GeodeticPoint kNaro{34.43 * kDeg, 127.53 * kDeg, 0.0};
const sim::GeodeticPoint kJeju{33.28 * kDeg, 126.46 * kDeg, 100.0};

// Sites as the pipeline hands them to the node (the top-level sites: map becomes this list).
const std::string kSites =
    "sites: [{name: naro, latitude: 34.43 deg, longitude: 127.53 deg, height: 0 m},"
    " {name: jeju, latitude: 33.28 deg, longitude: 126.46 deg, height: 100 m}]\n"
    "frame_origin: jeju\n";
const std::string kLaunch = kSites + "profile: kslv1\nearth: wgs84\npad_site: naro\nlaunch_azimuth: 170 deg\n";

using test::config_error;
using test::fly;

}  // namespace

// geodetic -> ECEF (GeographicLib) -> ENU (rotation at the origin) -> geodetic (LocalCartesian
// reverse) returns every point within 1 mm, out to 3000 km from the origin and 1000 km up; the
// ENU coordinates agree with GeographicLib's own LocalCartesian forward within 1 mm.
TEST_CASE("geodetic round trip within 1 mm over 3000 km") {
  const sim::EnuFrame frame(kJeju);
  const GeographicLib::Geodesic& g = GeographicLib::Geodesic::WGS84();
  double worst = 0.0, worst_enu = 0.0, farthest = 0.0;
  for (double azimuth = 0; azimuth < 360; azimuth += 30)
    for (double distance : {0.0, 1e3, 150e3, 1000e3, 2000e3, 3000e3})
      for (double height : {-50.0, 0.0, 10e3, 300e3, 1000e3}) {
        double lat = 0, lon = 0;
        g.Direct(kJeju.latitude / kDeg, kJeju.longitude / kDeg, azimuth, distance, lat, lon);
        const sim::GeodeticPoint p{lat * kDeg, lon * kDeg, height};
        const Vec3 enu = frame.to_enu(p);
        const sim::GeodeticPoint back = frame.to_geodetic(enu);
        const Vec3 again = frame.ecef(back), first = frame.ecef(p);
        worst = std::max(worst, (again - first).norm());
        Vec3 lc;
        frame.local().Forward(lat, lon, height, lc.x(), lc.y(), lc.z());
        worst_enu = std::max(worst_enu, (lc - enu).norm());
        farthest = std::max(farthest, enu.norm());
        CHECK(back.height == Approx(height).margin(1e-3));
      }
  INFO("worst round trip " << worst << " m, ENU vs LocalCartesian " << worst_enu << " m");
  CHECK(farthest > 3000e3);
  CHECK(worst < 1e-3);
  CHECK(worst_enu < 1e-3);
  // The origin is the origin, and its up is the frame's z.
  CHECK(frame.to_enu(kJeju).norm() < 1e-6);
  CHECK((frame.up_at(kJeju) - Vec3::UnitZ()).norm() < 1e-12);
}

// The foot point of every table row is `downrange` along the geodesic from the pad at the launch
// azimuth and the vehicle is `altitude - 0.1 km` above the ellipsoid there.
TEST_CASE("wgs84 launch keeps geodesic downrange and height") {
  const sim::EnuFrame frame(kJeju);
  const sim::GeodeticLaunchPath path(sim::kslv1_table(), kNaro, 170 * kDeg, frame);
  const GeographicLib::Geodesic& g = GeographicLib::Geodesic::WGS84();
  const auto& table = sim::kslv1_table();
  for (size_t i = 0; i < table.time.size(); ++i) {
    INFO("t = " << table.time[i]);
    const sim::GeodeticPoint p = frame.to_geodetic(path.at(table.time[i]).position);
    double s12 = 0, azi1 = 0, azi2 = 0;
    g.Inverse(kNaro.latitude / kDeg, kNaro.longitude / kDeg, p.latitude / kDeg, p.longitude / kDeg, s12, azi1, azi2);
    CHECK(s12 == Approx(table.downrange[i]).margin(1e-3));
    if (s12 > 1.0) CHECK(azi1 == Approx(170.0).margin(1e-6));
    CHECK(p.height == Approx(table.altitude[i] - table.altitude[0]).margin(1e-3));
  }
  CHECK((path.at(0).position - frame.to_enu(kNaro)).norm() < 1e-6);
}

// Velocity and acceleration are the time derivatives of the position (central differences of
// the path itself, 10 ms apart; the tolerance is their truncation and rounding error). The times
// lie between the profile table's rows: its monotone interpolation is C1, so the acceleration may
// step at a row and a central difference across one measures the step, not the derivative.
TEST_CASE("wgs84 launch velocity and acceleration are derivatives") {
  const sim::EnuFrame frame(kJeju);
  const sim::GeodeticLaunchPath path(sim::kslv1_table(), kNaro, 170 * kDeg, frame);
  const double h = 1e-2;
  for (double t : {10.0, 54.5, 120.0, 230.5, 300.0, 420.0, 500.0, 539.0}) {
    INFO("t = " << t);
    const auto k = path.at(t), kp = path.at(t + h), km = path.at(t - h);
    const Vec3 v = (kp.position - km.position) / (2 * h);
    const Vec3 a = (kp.velocity - km.velocity) / (2 * h);
    CHECK((v - k.velocity).norm() < 1e-3 * std::max(1.0, k.velocity.norm() * 1e-3));
    CHECK((a - k.acceleration).norm() < 2e-3);
  }
}

// From a radar on Jeju (the frame's origin) the ascent is below 2 deg of elevation at first, climbs,
// then sets: the elevation falls through 10 deg and 2 deg in the last two minutes of the flight.
TEST_CASE("wgs84 launch elevation from Jeju falls below 2 deg") {
  const auto truths = fly("rate: 1 Hz\n" + kLaunch);
  REQUIRE(truths.size() == 541);
  auto elevation = [](const Vec3& p) { return std::atan2(p.z(), std::hypot(p.x(), p.y())) / kDeg; };
  double peak = -90, t_peak = 0, t10 = -1, t2 = -1;
  for (const Truth& t : truths) {
    const double el = elevation(t.position);
    if (el > peak) peak = el, t_peak = t.time;
    if (t.time > t_peak && t10 < 0 && el < 10) t10 = t.time;
    if (t.time > t_peak && t2 < 0 && el < 2) t2 = t.time;
  }
  INFO("peak " << peak << " deg at " << t_peak << " s, 10 deg at " << t10 << " s, 2 deg at " << t2 << " s");
  CHECK(elevation(truths.front().position) < 0);  // the pad is below Jeju's horizon
  CHECK(peak > 20);
  CHECK(t10 > 350);
  CHECK(t2 > t10 + 60);
  CHECK(t2 < 540);
}

TEST_CASE("wgs84 launch parameters are checked") {
  struct Case {
    std::string yaml;
    const char* name;
  };
  const Case cases[] = {
      {kSites + "profile: kslv1\nearth: wgs84\nlaunch_azimuth: 170 deg", "pad_site"},
      {kSites + "profile: kslv1\nearth: wgs84\npad_site: naru\nlaunch_azimuth: 170 deg", "pad_site"},
      {kLaunch + "pad_position: [0, 0, 0]", "pad_position"},
      {"sites: [{name: naro, latitude: 34.43 deg, longitude: 127.53 deg}]\nprofile: kslv1\nearth: wgs84\n"
       "pad_site: naro\nlaunch_azimuth: 170 deg",
       "earth"},
      {kSites + "profile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 0 deg\npad_site: naro", "pad_site"},
      {kSites + "initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]\npad_site: naro",
       "pad_site"},
      {"sites: [{name: naro, latitude: 95 deg, longitude: 127.53 deg}]\nframe_origin: naro\nprofile: kslv1\nearth: "
       "wgs84\npad_site: naro\nlaunch_azimuth: 170 deg",
       "latitude"},
  };
  for (const auto& c : cases) {
    INFO(c.yaml);
    CHECK_THAT(config_error(c.yaml), Catch::Matchers::Contains(std::string("'") + c.name + "'"));
  }
  CHECK_THAT(config_error(kSites + "profile: kslv1\nearth: wgs84\npad_site: naru\nlaunch_azimuth: 170 deg"),
             Catch::Matchers::Contains("sites: naro, jeju"));
  CHECK(config_error(kLaunch).empty());
  // Sites handed to a segment trajectory are the pipeline's, not an error.
  CHECK(config_error(kSites + "initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]").empty());
}
