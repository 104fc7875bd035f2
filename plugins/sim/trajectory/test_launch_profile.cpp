// Purpose: tests of the cubic spline, the monotone cubic and the KSLV-I launch profile: table points, continuity, no backward motion, placement, sampling.
#include "cubic_spline.hpp"
#include "launch_profile.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "trajectory_test_support.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

using namespace trackflow;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Paper 000 Table 16, typed from the paper: time s, altitude km, downrange km.
const double kTable16[][3] = {{0, 0.1, 0},     {0.2, 0.1, 0},   {54, 7.2, 0.8},     {215, 177, 245},    {229, 193, 303},
                              {232, 196, 316}, {395, 303, 1052}, {453, 304, 1390}, {540, 302, 2054}};

using test::config_error;
using test::fly;

sim::LaunchPath path(const Vec3& pad, double azimuth_deg, bool spherical) {
  return sim::LaunchPath(sim::kslv1_table(), {pad, azimuth_deg * kDeg, spherical});
}

}  // namespace

// cubic spline: reproduces a cubic that meets its end conditions, and is C2 at the knots
TEST_CASE("cubic spline reproduces a cubic and is C2") {
  // p(x) = 2 - x + 0.5 x^2 - 0.1 x^3 has p''(x) = 1 - 0.6 x, zero at x = 5/3: natural there.
  auto p = [](double x) { return 2 - x + 0.5 * x * x - 0.1 * x * x * x; };
  auto dp = [](double x) { return -1 + x - 0.3 * x * x; };
  auto ddp = [](double x) { return 1 - 0.6 * x; };
  const std::vector<double> x = {-1.0, -0.7, 0.0, 0.2, 1.1, 5.0 / 3.0};
  std::vector<double> y;
  for (double v : x) y.push_back(p(v));
  const sim::CubicSpline s(x, y, sim::SplineEnd::clamped_to(dp(-1.0)), sim::SplineEnd::natural());
  for (double t = -1.0; t <= 5.0 / 3.0; t += 0.01) {
    const auto q = s.at(t);
    CHECK(q.value == Approx(p(t)).margin(1e-12));
    CHECK(q.first == Approx(dp(t)).margin(1e-11));
    CHECK(q.second == Approx(ddp(t)).margin(1e-10));
  }
  // Both ends clamped also reproduces it.
  const sim::CubicSpline c(x, y, sim::SplineEnd::clamped_to(dp(-1.0)), sim::SplineEnd::clamped_to(dp(5.0 / 3.0)));
  CHECK(c.at(0.5).value == Approx(p(0.5)).margin(1e-12));
  // Generic data: continuity of value, slope and curvature across each interior knot.
  const sim::CubicSpline g({0, 1, 1.5, 4, 4.2, 9}, {0, 3, -1, 2, 2, 10}, sim::SplineEnd::natural(), sim::SplineEnd::natural());
  for (double k : {1.0, 1.5, 4.0, 4.2}) {
    const auto lo = g.at(k - 1e-9), hi = g.at(k + 1e-9);
    CHECK(std::abs(lo.value - hi.value) < 1e-7);
    CHECK(std::abs(lo.first - hi.first) < 1e-6);
    CHECK(std::abs(lo.second - hi.second) < 1e-6);
  }
  CHECK(g.at(0).second == Approx(0).margin(1e-12));
  CHECK(g.at(9).second == Approx(0).margin(1e-12));
  CHECK_THROWS_AS(sim::CubicSpline({0, 1, 1}, {0, 1, 2}, {}, {}), std::invalid_argument);
}

// monotone cubic: equals the C2 spline where no slope is limited; monotone and bounded otherwise
TEST_CASE("monotone cubic keeps the spline or limits it") {
  // Monotone data of a gentle function: nothing is limited, so it is the spline itself.
  const std::vector<double> x = {0, 1, 2.5, 3, 4.5, 6};
  std::vector<double> y;
  for (double v : x) y.push_back(v + 0.1 * std::sin(v));
  const sim::CubicSpline spline(x, y, sim::SplineEnd::natural(), sim::SplineEnd::natural());
  const sim::MonotoneCubic same(x, y, sim::SplineEnd::natural(), sim::SplineEnd::natural());
  CHECK(same.limited_knots().empty());
  for (double t = 0; t <= 6; t += 0.05) {
    CHECK(same.at(t).value == Approx(spline.at(t).value).margin(1e-12));
    CHECK(same.at(t).first == Approx(spline.at(t).first).margin(1e-12));
    CHECK(same.at(t).second == Approx(spline.at(t).second).margin(1e-10));
  }
  // A plateau and a jump (Table 16's shape in miniature): the spline overshoots, the monotone
  // cubic neither decreases nor leaves each interval's range, passes through every point, and its
  // slope is zero at the plateau and at the maximum.
  const std::vector<double> xs = {0, 0.2, 5, 20, 30, 40}, ys = {0, 0, 1, 200, 210, 205};
  const sim::CubicSpline wild(xs, ys, sim::SplineEnd::clamped_to(0), sim::SplineEnd::natural());
  const sim::MonotoneCubic tame(xs, ys, sim::SplineEnd::clamped_to(0), sim::SplineEnd::natural());
  double spline_min = 0;
  for (double t = 0; t <= 5; t += 0.01) spline_min = std::min(spline_min, wild.at(t).value);
  CHECK(spline_min < -1);  // the overshoot the limiter exists for
  CHECK_FALSE(tame.limited_knots().empty());
  for (size_t i = 0; i < xs.size(); ++i) CHECK(tame.at(xs[i]).value == Approx(ys[i]).margin(1e-12));
  CHECK(tame.slopes()[1] == 0.0);
  CHECK(tame.slopes()[4] == 0.0);
  for (size_t i = 0; i + 1 < xs.size(); ++i) {
    const double lo = std::min(ys[i], ys[i + 1]), hi = std::max(ys[i], ys[i + 1]);
    const double sign = ys[i + 1] >= ys[i] ? 1.0 : -1.0;
    double last = ys[i];
    for (double t = xs[i]; t <= xs[i + 1]; t += (xs[i + 1] - xs[i]) / 200) {
      const auto q = tame.at(t);
      INFO("t = " << t);
      CHECK(q.value >= lo - 1e-12);
      CHECK(q.value <= hi + 1e-12);
      CHECK(sign * q.first >= -1e-12);
      CHECK(sign * (q.value - last) >= -1e-12);
      last = q.value;
    }
  }
  // The derivatives are those of the value (central differences inside a piece).
  for (double t : {0.1, 2.0, 12.0, 25.0, 35.0}) {
    const double h = 1e-5;
    CHECK((tame.at(t + h).value - tame.at(t - h).value) / (2 * h) == Approx(tame.at(t).first).margin(1e-6));
    CHECK((tame.at(t + h).first - tame.at(t - h).first) / (2 * h) == Approx(tame.at(t).second).margin(1e-5));
  }
}

// KSLV-I profile passes through every row of paper 000 Table 16
TEST_CASE("KSLV-I profile passes through paper 000 Table 16") {
  // 5 Hz puts a sample on every table time; pad at the origin, launched due east (flat earth).
  const auto truths = fly("rate: 5 Hz\nprofile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 90 deg");
  REQUIRE(truths.size() == 540 * 5 + 1);
  for (const auto& row : kTable16) {
    INFO("t = " << row[0]);
    const Truth& t = truths.at(static_cast<size_t>(std::lround(row[0] * 5)));
    REQUIRE(t.time == row[0]);
    CHECK(t.position.x() == Approx(row[2] * 1e3).margin(1e-6));
    CHECK(t.position.y() == Approx(0).margin(1e-6));
    CHECK(t.position.z() == Approx((row[1] - 0.1) * 1e3).margin(1e-6));
  }
  // At rest at lift-off.
  CHECK(truths[0].velocity.norm() < 1e-12);
}

// KSLV-I velocity is continuous and velocity and acceleration are the derivatives of the position
TEST_CASE("KSLV-I velocity and acceleration are derivatives") {
  for (bool spherical : {false, true}) {
    INFO((spherical ? "spherical" : "flat"));
    const auto lp = path(Vec3(-60e3, 80e3, 30), 160, spherical);
    // Across each interior knot the velocity is continuous (a jump would show at once; over 2e-7 s
    // the acceleration moves it by < 1e-5). The acceleration is continuous where the monotone
    // limiter left the spline alone (the 229 s knot and its neighbours' pieces); next to a limited
    // slope it jumps, by at most 9.0 m/s^2 (altitude at the 395 s row).
    for (int i = 1; i < 8; ++i) {
      const double k = kTable16[i][0];
      INFO("knot " << k);
      const auto lo = lp.at(k - 1e-7), hi = lp.at(k + 1e-7);
      CHECK((lo.velocity - hi.velocity).norm() < 1e-4);
      CHECK((lo.acceleration - hi.acceleration).norm() < (k == 229 ? 1e-4 : 10.0));
    }
    // Central differences of position and velocity match the reported velocity and acceleration
    // anywhere at least h from a knot, where the jerk jumps (by ~10 m/s^3 around the 3 s
    // stage-separation interval) and the velocity difference errs by jump * h / 4 = 2.5e-4 m/s^2
    // at h = 1e-4 s; rounding adds ~1e-5 m/s. At a knot the position difference still gives the
    // velocity (C1).
    const double h = 1e-4;
    for (double t = 0.5; t < 539.5; t += 0.37) {
      for (double tt : {t, std::floor(t)}) {
        INFO("t = " << tt);
        const auto k = lp.at(tt), a = lp.at(tt - h), b = lp.at(tt + h);
        CHECK(((b.position - a.position) / (2 * h) - k.velocity).norm() < 1e-3);
        bool at_knot = false;
        for (const auto& row : kTable16) at_knot |= std::abs(tt - row[0]) < 2 * h;
        if (!at_knot) CHECK(((b.velocity - a.velocity) / (2 * h) - k.acceleration).norm() < 1e-3);
      }
    }
  }
}

// Issue 8: a C2 spline through Table 16 swung 254.7 m uprange near 28 s, the rocket moving
// backwards at 12 m/s. Over the whole 540 s, at the pipeline's 40 Hz and between samples: the
// downrange distance never decreases, the altitude never decreases up to the 304 km row at 453 s
// and never increases after it (Table 16 ends at 302 km), never leaving the rows either side.
TEST_CASE("KSLV-I profile never moves backwards") {
  for (bool spherical : {false, true}) {
    INFO((spherical ? "spherical" : "flat"));
    const Vec3 pad(-100e3, 0, 0);
    const auto lp = path(pad, 170, spherical);
    const Vec3 centre(0, 0, -sim::kEarthRadius), up = (pad - centre).normalized();
    const Vec3 along(std::sin(170 * kDeg), std::cos(170 * kDeg), 0);
    // Downrange and altitude of a position: flat, along the track and up; spherical, the arc and
    // the height above the pad's radius.
    auto downrange = [&](const Vec3& p) {
      if (!spherical) return (p - pad).dot(along);
      const Vec3 r = p - centre;
      return std::atan2(r.cross(up).norm(), r.dot(up)) * sim::kEarthRadius;
    };
    auto altitude = [&](const Vec3& p) { return spherical ? (p - centre).norm() - (pad - centre).norm() : p.z() - pad.z(); };
    double last_d = downrange(lp.at(0).position), last_h = altitude(lp.at(0).position);
    long long samples = 0;
    for (long long k = 1; k <= 540 * 400; ++k) {  // 400 Hz: ten points between 40 Hz samples
      const double t = static_cast<double>(k) / 400.0;
      const auto s = lp.at(t);
      const double d = downrange(s.position), hv = altitude(s.position);
      INFO("t = " << t);
      // 1e-6 m: rounding of the placement (positions ~1e6 m).
      if (d < last_d - 1e-6) CHECK(d >= last_d - 1e-6);
      if (t <= 453 && hv < last_h - 1e-6) CHECK(hv >= last_h - 1e-6);
      if (t > 453 && hv > last_h + 1e-6) CHECK(hv <= last_h + 1e-6);
      if (t > 453) {
        CHECK(hv <= 303.9e3 + 1e-6);
        CHECK(hv >= 301.9e3 - 1e-6);
      }
      last_d = d;
      last_h = hv;
      ++samples;
    }
    CHECK(samples == 540 * 400);
    // The apogee is the 304 km row itself (the limiter sets the slope 0 at the data's maximum).
    CHECK(altitude(lp.at(453).position) == Approx(303.9e3).margin(1e-3));
  }
  // The same through the plugin at the pipeline's 40 Hz: never a sample with an uprange velocity.
  const auto truths = fly("rate: 40 Hz\nprofile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 0 deg");
  REQUIRE(truths.size() == 540 * 40 + 1);
  for (size_t i = 1; i < truths.size(); ++i) {
    INFO("t = " << truths[i].time);
    if (truths[i].velocity.y() < 0) CHECK(truths[i].velocity.y() >= 0);
    if (truths[i].position.y() < truths[i - 1].position.y()) CHECK(truths[i].position.y() >= truths[i - 1].position.y());
  }
}

TEST_CASE("KSLV-I profile is physically sensible") {
  const auto truths = fly("rate: 10 Hz\nprofile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 0 deg");
  double max_speed = 0.0, time_of_max = 0.0, max_altitude = 0.0, min_altitude = 1e9, min_downrange = 0.0, max_accel = 0.0;
  for (const Truth& t : truths) {
    const double speed = t.velocity.norm();
    if (speed > max_speed) max_speed = speed, time_of_max = t.time;
    max_altitude = std::max(max_altitude, t.position.z());
    min_altitude = std::min(min_altitude, t.position.z());
    min_downrange = std::min(min_downrange, t.position.y());
    max_accel = std::max(max_accel, t.acceleration.norm());
  }
  // Orbit insertion (paper 000: ~302 km, 2054 km downrange at 540 s) at 7-8.5 km/s, at the end.
  CHECK(max_speed > 7000);
  CHECK(max_speed < 8500);
  CHECK(time_of_max > 500);
  CHECK(truths.back().velocity.norm() == Approx(max_speed));
  // Never below the pad; apogee the 304 km row (303.9 km above the 0.1 km pad), not above it.
  CHECK(min_altitude > -1e-3);
  CHECK(max_altitude < 303.9e3 + 1e-3);
  // Never uprange of the pad (the C2 spline drifted 254.7 m uprange near 28 s), clear of it after Mach 1.
  CHECK(min_downrange >= 0);
  for (const Truth& t : truths)
    if (t.time > 54) CHECK(t.position.y() > 0);
  CHECK(max_accel < 5 * 9.81);
  // Mach 1 (about 300 m/s) is passed near 54 s, as the table says.
  const double v54 = truths[540].velocity.norm();
  CHECK(v54 > 250);
  CHECK(v54 < 500);
}

// the launch track starts at the pad and runs along the launch azimuth
TEST_CASE("launch track starts at the pad along the azimuth") {
  const auto truths = fly("rate: 1 Hz\nprofile: kslv1\npad_position: [100 km, -20 km, 5 m]\nlaunch_azimuth: 170 deg");
  const Vec3 pad(100e3, -20e3, 5), track(std::sin(170 * kDeg), std::cos(170 * kDeg), 0);
  CHECK((truths[0].position - pad).norm() < 1e-9);
  for (const Truth& t : truths) {
    const Vec3 d = t.position - pad;
    CHECK(std::abs(d.x() * track.y() - d.y() * track.x()) < 1e-6);  // no cross-track component
    CHECK(d.dot(track) > -1e-6);
    CHECK(std::abs(t.velocity.x() * track.y() - t.velocity.y() * track.x()) < 1e-9);
  }
  CHECK((truths.back().position - (pad + 2054e3 * track + Vec3(0, 0, 301.9e3))).norm() < 1e-6);
}

// spherical earth: altitude above the sphere and great-circle downrange are kept
TEST_CASE("spherical earth keeps altitude and downrange") {
  const Vec3 pad(-100e3, 30e3, 40);  // e.g. a pad 100 km west of the radar at the origin
  const auto flat = path(pad, 100, false), round = path(pad, 100, true);
  const Vec3 centre(0, 0, -sim::kEarthRadius);
  const Vec3 up = (pad - centre).normalized();
  const double pad_radius = (pad - centre).norm();
  for (const auto& row : kTable16) {
    INFO("t = " << row[0]);
    const Vec3 p = round.at(row[0]).position - centre;
    CHECK(p.norm() - pad_radius == Approx((row[1] - 0.1) * 1e3).margin(1e-6));
    const double arc = std::atan2(p.cross(up).norm(), p.dot(up)) * sim::kEarthRadius;
    CHECK(arc == Approx(row[2] * 1e3).margin(1e-6));
  }
  // The vehicle ends below the pad's horizon.
  CHECK((round.at(540).position - pad).dot(up) < 0);
  // Against the flat track from a pad at the origin (same local vertical): early on the curvature
  // hardly matters (0.9 m: 7.1 km of altitude over 0.8 km of arc), at orbit insertion the vehicle is
  // (R + h) cos(d / R) - R below the tangent plane instead of h above it.
  const auto flat0 = path(Vec3::Zero(), 100, false), round0 = path(Vec3::Zero(), 100, true);
  CHECK((round0.at(54).position - flat0.at(54).position).norm() < 1.5);
  const double R = sim::kEarthRadius, h = 301.9e3, d = 2054e3;
  CHECK(flat0.at(540).position.z() - round0.at(540).position.z() == Approx(h - ((R + h) * std::cos(d / R) - R)).margin(1e-3));
  CHECK(std::hypot(round0.at(540).position.x(), round0.at(540).position.y()) == Approx((R + h) * std::sin(d / R)).margin(1e-3));
}

// launch sampling: start_time shifts lift-off, rate sets the samples, profile_duration cuts
TEST_CASE("launch sampling: start_time/rate/profile_duration") {
  const auto truths = fly("rate: 40 Hz\nstart_time: 10 s\nprofile: kslv1\npad_position: [0, 0, 0]\n"
                          "launch_azimuth: 45 deg\nprofile_duration: 200 s");
  REQUIRE(truths.size() == 200 * 40 + 1);
  for (size_t k = 0; k < truths.size(); ++k) CHECK(truths[k].time == 10.0 + static_cast<double>(k) / 40.0);
  CHECK(truths.back().time == 210.0);
  const Truth& mach1 = truths[54 * 40];  // 54 s after lift-off
  CHECK(mach1.position.z() == Approx(7.1e3).margin(1e-6));
  CHECK(std::hypot(mach1.position.x(), mach1.position.y()) == Approx(800).margin(1e-6));
  CHECK(fly("rate: 40 Hz\nprofile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 0 deg").size() == 540 * 40 + 1);
}

TEST_CASE("launch-profile parameters are checked against the mode") {
  const std::string launch = "profile: kslv1\npad_position: [0, 0, 0]\nlaunch_azimuth: 90 deg\n";
  struct Case {
    std::string yaml;
    const char* name;
  };
  const Case cases[] = {
      {launch + "segments: [{type: constant_velocity, duration: 1 s}]", "segments"},
      {launch + "initial_position: [0, 0, 0]", "initial_position"},
      {launch + "initial_velocity: [1, 0, 0]", "initial_velocity"},
      {"profile: kslv1\nlaunch_azimuth: 90 deg", "pad_position"},
      {"profile: kslv1\npad_position: [0, 0, 0]", "launch_azimuth"},
      {launch + "profile_duration: 541 s", "profile_duration"},
      {launch + "earth: round", "earth"},
      {"initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]\npad_position: [0, 0, 0]",
       "pad_position"},
      {"initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]\nearth: spherical", "earth"},
      {"profile: falcon9\npad_position: [0, 0, 0]\nlaunch_azimuth: 0", "profile"},
  };
  for (const auto& c : cases) {
    INFO(c.yaml);
    CHECK_THAT(config_error(c.yaml), Catch::Matchers::Contains(std::string("'") + c.name + "'"));
  }
  CHECK(config_error(launch + "earth: spherical\nprofile_duration: 540 s").empty());
}
