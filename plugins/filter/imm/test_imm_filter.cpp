// Purpose: tests of filter.imm through the plugin loader: probabilities sum to 1 and favour the right mode, a mode held certain equals filter.ekf, parameter checks.
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "plugin_fixture.hpp"
#include "estimation/radar_filter_test_support.hpp"

using namespace trackflow;
using namespace trackflow::filter_test;

namespace {

const std::string kModes =
    "modes: [{ motion: constant_velocity, q: 1 m2/s3 }, { motion: constant_acceleration, q_jerk: 10 m2/s5 }, "
    "{ motion: singer, singer_alpha: 0.5 1/s, singer_sigma: 20 m/s2 }]";

std::string imm_params(const std::string& transition, const std::string& extra = "") {
  return "{ " + kModes + ", transition: " + transition + extra + " }";
}

// 40 s at 10 Hz from a radar at the origin: straight and level for 20 s, then 30 m/s2 along x.
struct Flight {
  Vec3 p{-5000, 20000, 3000}, v{200, 0, 0};
  Vec3 accel(double t) const { return t < 20.0 ? Vec3::Zero() : Vec3(30, 0, 0); }
};

}  // namespace

TEST_CASE("mode probabilities sum to 1 and follow the manoeuvre") {
  FilterRun f("filter.imm", imm_params("[0.95, 0.025, 0.025, 0.025, 0.95, 0.025, 0.025, 0.025, 0.95]"), 0, "imm");
  Rng rng(7);
  Flight flight;
  const double T = 0.1;
  double cv_before = 0.0, accel_after = 0.0;
  int n_before = 0, n_after = 0;
  for (int k = 0; k < 400; ++k) {
    const double t = k * T;
    const Estimate& e = f.feed(radar(t, flight.p, flight.v, Vec3::Zero(), RadarNoise{}, &rng, true));
    const Vec3 a = flight.accel(t);
    flight.p += flight.v * T + 0.5 * a * T * T;
    flight.v += a * T;
    REQUIRE(e.annotation_count == 3);
    if (!e.initialised) continue;
    REQUIRE(e.state.size() == 9);
    const double sum = e.annotations[0] + e.annotations[1] + e.annotations[2];
    CHECK(sum == Approx(1.0).epsilon(1e-12));
    for (int j = 0; j < 3; ++j) CHECK((e.annotations[j] >= 0.0 && e.annotations[j] <= 1.0));
    REQUIRE(symmetric_pd(e.covariance));
    if (t > 10.0 && t < 20.0) {
      cv_before += e.annotations[0];
      ++n_before;
    }
    if (t > 25.0) {
      accel_after += e.annotations[1] + e.annotations[2];
      ++n_after;
    }
  }
  CHECK(cv_before / n_before > 0.7);
  CHECK(accel_after / n_after > 0.8);
}

TEST_CASE("an IMM certain of its CV mode equals filter.ekf") {
  FilterRun imm("filter.imm", imm_params("[1, 0, 0, 0, 1, 0, 0, 0, 1]", ", initial_probabilities: [1, 0, 0]"), 0, "imm");
  FilterRun ekf("filter.ekf", "{ motion: constant_velocity, q: 1 m2/s3 }", 0, "ekf");
  Rng rng(3);
  Flight flight;
  for (int k = 0; k < 150; ++k) {
    const Measurement m = radar(0.1 * k, flight.p, flight.v, Vec3::Zero(), RadarNoise{}, &rng, true);
    flight.p += flight.v * 0.1;
    const Estimate& a = imm.feed(m);
    const Estimate& b = ekf.feed(m);
    REQUIRE(a.initialised == b.initialised);
    if (!a.initialised) continue;
    CHECK(a.annotations[0] == 1.0);
    for (int i = 0; i < 6; ++i) {
      CHECK(a.enu(i) == Approx(b.enu(i)).margin(1e-9));
      for (int j = 0; j < 6; ++j) CHECK(a.enu_covariance(i, j) == Approx(b.enu_covariance(i, j)).margin(1e-9));
    }
    CHECK(a.nis == Approx(b.nis).margin(1e-9));
  }
}

TEST_CASE("IMM parameter errors name the parameter") {
  auto message = [](const std::string& params) {
    try {
      test::make("filter.imm", params, "imm");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message(imm_params("[0.9, 0.1, 0, 0, 1, 0, 0, 0, 0.9]")).find("row 3") != std::string::npos);
  CHECK(message(imm_params("[0.5, 0.5, 0.5, 0.5]")).find("9") != std::string::npos);
  CHECK(message(imm_params("[1, 0, 0, 0, 1, 0, 0, 0, 1]", ", initial_probabilities: [0.5, 0.5, 0.5]"))
            .find("initial_probabilities") != std::string::npos);
  CHECK(message("{ modes: [{ motion: singer, singer_alpha: 1 1/s, singer_sigma: 1 m/s2 }, { motion: singer, "
                "singer_alpha: 2 1/s, singer_sigma: 1 m/s2 }], transition: [0.5, 0.5, 0.5, 0.5] }")
            .find("distinct name") != std::string::npos);
  CHECK(message("{ modes: [{ motion: constant_velocity }], transition: [1] }").find("2 to 4") != std::string::npos);
  CHECK(message("{ modes: [{ motion: constant_velocity, q_jerk: 1 m2/s5 }, { motion: singer, singer_alpha: 1 1/s, "
                "singer_sigma: 1 m/s2 }], transition: [0.5, 0.5, 0.5, 0.5] }")
            .find("q_jerk") != std::string::npos);
}

namespace {

// The component form: each mode a nested filter, created by the host from its own declaration.
const std::string kEkfUkf =
    "modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, "
    "{ type: filter.ukf, motion: constant_acceleration, q_jerk: 100 m2/s5 }], transition: [0.95, 0.05, 0.05, 0.95]";

std::string config_error(const std::string& params) {
  try {
    test::make("filter.imm", params, "imm");
  } catch (const ConfigError& e) {
    return e.message();
  }
  return "no error";
}

}  // namespace

TEST_CASE("component modes: an EKF and a UKF track a manoeuvre") {
  FilterRun f("filter.imm", "{ " + kEkfUkf + " }", 0, "imm");
  const std::vector<std::string> names = dynamic_cast<Filter&>(*f.filter).annotation_names();
  REQUIRE(names == std::vector<std::string>{"p_ekf_cv", "p_ukf_ca"});
  Rng rng(11);
  Flight flight;
  const RadarNoise noise;
  const double T = 0.1;
  double cv_before = 0.0, ca_after = 0.0, se = 0.0, sigma2 = 0.0;
  int n_before = 0, n_after = 0, n = 0;
  for (int k = 0; k < 400; ++k) {
    const double t = k * T;
    const Estimate& e = f.feed(radar(t, flight.p, flight.v, Vec3::Zero(), noise, &rng, true));
    const Vec3 truth = flight.p;
    const Vec3 a = flight.accel(t);
    flight.p += flight.v * T + 0.5 * a * T * T;
    flight.v += a * T;
    if (!e.initialised) continue;
    REQUIRE(e.state.size() == 9);
    CHECK(e.annotations[0] + e.annotations[1] == Approx(1.0).epsilon(1e-12));
    REQUIRE(symmetric_pd(e.covariance));
    if (t > 10.0 && t < 20.0) {
      cv_before += e.annotations[0];
      ++n_before;
    }
    if (t > 25.0) {
      ca_after += e.annotations[1];
      ++n_after;
    }
    if (t > 2.0) {
      se += (e.enu.head<3>() - truth).squaredNorm();
      const double r = truth.norm();  // one measurement's position error: range and two angles
      sigma2 += noise.range * noise.range + r * r * (noise.azimuth * noise.azimuth + noise.elevation * noise.elevation);
      ++n;
    }
  }
  CHECK(cv_before / n_before > 0.6);
  CHECK(ca_after / n_after > 0.7);
  // Filtering beats a single measurement's position error (~29 m at 20 km) by a clear margin.
  CHECK(std::sqrt(se / n) < 0.6 * std::sqrt(sigma2 / n));
}

TEST_CASE("component EKF modes equal the record form") {
  const std::string transition = ", transition: [0.9, 0.1, 0.1, 0.9] }";
  FilterRun rec("filter.imm",
                "{ modes: [{ motion: constant_velocity, q: 1 m2/s3 }, { motion: constant_acceleration, q_jerk: 100 m2/s5 "
                "}]" + transition,
                0, "rec");
  FilterRun cmp("filter.imm",
                "{ modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: filter.ekf, motion: "
                "constant_acceleration, q_jerk: 100 m2/s5 }]" + transition,
                0, "cmp");
  Rng rng(5);
  Flight flight;
  for (int k = 0; k < 400; ++k) {
    const double t = 0.1 * k;
    const Measurement m = radar(t, flight.p, flight.v, Vec3::Zero(), RadarNoise{}, &rng, k % 2 == 0);
    const Vec3 a = flight.accel(t);
    flight.p += flight.v * 0.1 + 0.005 * a;
    flight.v += a * 0.1;
    const Estimate& x = rec.feed(m);
    const Estimate& y = cmp.feed(m);
    REQUIRE(x.initialised == y.initialised);
    if (!x.initialised) continue;
    REQUIRE(x.state.size() == y.state.size());
    for (int i = 0; i < x.state.size(); ++i) {
      CHECK(y.state(i) == Approx(x.state(i)).epsilon(1e-12).margin(1e-9));
      for (int j = 0; j < x.state.size(); ++j)
        CHECK(y.covariance(i, j) == Approx(x.covariance(i, j)).epsilon(1e-12).margin(1e-9));
    }
    CHECK(y.annotations[0] == Approx(x.annotations[0]).margin(1e-12));
    CHECK(y.nis == Approx(x.nis).epsilon(1e-10).margin(1e-12));
  }
}

TEST_CASE("component modes: configuration errors") {
  // A filter whose estimator cannot take a mixed state, or measures in another frame.
  CHECK_THAT(config_error("{ modes: [{ type: filter.ekf }, { type: filter.kalman }], transition: [0.5, 0.5, 0.5, 0.5] }"),
             Catch::Contains("mode 2 (filter.kalman)"));
  // Modes that would accept different measurements.
  CHECK_THAT(config_error("{ modes: [{ type: filter.ekf }, { type: filter.ukf, range_rate: ignore }], transition: [0.5, "
                          "0.5, 0.5, 0.5] }"),
             Catch::Contains("every mode must accept the same measurements"));
  // Records and components together; the record form's zenith on component modes.
  CHECK_THAT(config_error("{ modes: [{ type: filter.ekf }, { motion: constant_velocity }], transition: [0.5, 0.5, 0.5, "
                          "0.5] }"),
             Catch::Contains("not both"));
  CHECK_THAT(config_error("{ modes: [{ type: filter.ekf }, { type: filter.ukf }], transition: [0.5, 0.5, 0.5, 0.5], "
                          "zenith: textbook }"),
             Catch::Contains("set zenith in each mode"));
  // A misspelt nested key, at its own line and column.
  CHECK_THAT(config_error("{ modes: [{ type: filter.ekf }, { type: filter.ukf, q_jerkk: 1 m2/s5 }], transition: [0.5, "
                          "0.5, 0.5, 0.5] }"),
             Catch::Contains("unknown parameter 'q_jerkk' (did you mean 'q_jerk'?)"));
  // Two modes of the same type and motion get distinct names.
  FilterRun twin("filter.imm",
                 "{ modes: [{ type: filter.ekf, q: 1 m2/s3 }, { type: filter.ekf, q: 9 m2/s3 }], transition: [0.5, 0.5, "
                 "0.5, 0.5] }",
                 0, "imm");
  CHECK(dynamic_cast<Filter&>(*twin.filter).annotation_names() == std::vector<std::string>{"p_ekf_cv", "p_2_ekf"});
}
