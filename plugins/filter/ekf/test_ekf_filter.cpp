// Purpose: tests of filter.ekf: a textbook EKF reference, Monte Carlo consistency (CV, Singer), CA tracking, range rate, wrap, zenith, coasting, errors.
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "plugin_fixture.hpp"
#include "estimation/radar_filter_test_support.hpp"

using namespace trackflow;
using namespace trackflow::filter_test;

namespace {

struct Run : FilterRun {
  Run(const std::string& params, std::uint64_t run = 0) : FilterRun("filter.ekf", params, run, "ekf") {}
};

// Textbook EKF (dynamic sizes, P = (I - KH) P, numerical Jacobian of geometry.hpp's h).
struct ReferenceEkf {
  Eigen::VectorXd x;  // [x vx y vy z vz]
  Eigen::MatrixXd P;
  double q;
  bool planar = false;  // a 2-D radar's track: no z process noise
  void predict(double T) {
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(6, 6), Q = Eigen::MatrixXd::Zero(6, 6);
    for (int a = 0; a < 3; ++a) {
      F(2 * a, 2 * a + 1) = T;
      if (planar && a == 2) continue;
      Q(2 * a, 2 * a) = q * T * T * T / 3;
      Q(2 * a, 2 * a + 1) = Q(2 * a + 1, 2 * a) = q * T * T / 2;
      Q(2 * a + 1, 2 * a + 1) = q * T;
    }
    x = F * x;
    P = F * P * F.transpose() + Q;
  }
  static Eigen::VectorXd h(const Eigen::VectorXd& s, const Measurement& m) {
    const Vec3 d = Vec3(s(0), s(2), s(4)) - m.sensor_position, v(s(1), s(3), s(5));
    Eigen::VectorXd out(m.value.size());
    const Vec3 rae = enu_to_spherical(d, m.azimuth);
    if (m.frame == Frame::Polar) {  // a 2-D radar: [r, az(, rdot)]
      out.head<2>() = rae.head<2>();
      if (out.size() == 3) out(2) = range_rate(d, v);
      return out;
    }
    out.head<3>() = rae;
    if (out.size() == 4) out(3) = range_rate(d, v);
    return out;
  }
  void update(const Measurement& m) {
    const int n = static_cast<int>(m.value.size());
    Eigen::MatrixXd H(n, 6);
    for (int k = 0; k < 6; ++k) {
      const double step = 1e-5 * std::max(1.0, std::abs(x(k)));
      Eigen::VectorXd xp = x, xm = x;
      xp(k) += step;
      xm(k) -= step;
      Eigen::VectorXd dh = h(xp, m) - h(xm, m);
      dh(1) = std::remainder(dh(1), 2 * std::numbers::pi);
      H.col(k) = dh / (2 * step);
    }
    Eigen::VectorXd nu = Eigen::VectorXd(m.value) - h(x, m);
    nu(1) = std::remainder(nu(1), 2 * std::numbers::pi);
    const Eigen::MatrixXd S = H * P * H.transpose() + Eigen::MatrixXd(m.covariance);
    const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
    x += K * nu;
    P = (Eigen::MatrixXd::Identity(6, 6) - K * H) * P;
  }
};

}  // namespace

// CV EKF agrees step by step with a textbook EKF, with and without range rate, both conventions
TEST_CASE("CV EKF agrees step by step with a textbook EKF") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise})
    for (bool rr : {false, true}) {
      INFO("convention " << int(c) << " range rate " << rr);
      Run run("{ q: 4 m2/s3 }");
      Rng rng(21);
      const Vec3 sensor(100, -200, 10);
      const double T = 0.2;
      RadarNoise noise;
      std::vector<Measurement> ms;
      for (int k = 0; k < 50; ++k) {
        const double t = k * T;
        const Vec3 v(-120, 40, 8), p = Vec3(6e3, 9e3, 2e3) + v * t;
        ms.push_back(radar(t, p, v, sensor, noise, &rng, rr, c));
        run.feed(ms.back());
      }
      const auto& est = run.out.estimates;
      REQUIRE(est.size() == 50);
      CHECK_FALSE(est[0].initialised);
      CHECK(est[0].state.isZero());  // nothing to publish yet: zeros, never stale or uninitialised memory
      CHECK(est[0].enu_covariance.isZero());
      REQUIRE(est[1].initialised);
      // Reference initialised by classical conversion of the same two points.
      ReferenceEkf ref;
      ref.q = 4.0;
      ref.x = Eigen::VectorXd::Zero(6);
      ref.P = Eigen::MatrixXd::Zero(6, 6);
      Vec3 z[2];
      Mat3 R[2];
      for (int i = 0; i < 2; ++i) {
        const auto& v = ms[i].value;
        z[i] = spherical_to_enu(v(0), v(1), v(2), c) + sensor;
        const Mat3 J = spherical_to_enu_jacobian(v(0), v(1), v(2), c);
        R[i] = J * ms[i].covariance.topLeftCorner(3, 3) * J.transpose();
      }
      for (int a = 0; a < 3; ++a) {
        ref.x(2 * a) = z[1](a);
        ref.x(2 * a + 1) = (z[1](a) - z[0](a)) / T;
        for (int b = 0; b < 3; ++b) {
          ref.P(2 * a, 2 * b) = R[1](a, b);
          ref.P(2 * a, 2 * b + 1) = ref.P(2 * b + 1, 2 * a) = R[1](a, b) / T;
          ref.P(2 * a + 1, 2 * b + 1) = (R[0](a, b) + R[1](a, b)) / (T * T);
        }
      }
      CHECK((est[1].state - ref.x).norm() < 1e-9 * ref.x.norm());
      for (size_t k = 2; k < ms.size(); ++k) {
        ref.predict(T);
        ref.update(ms[k]);
        CHECK(est[k].updated);
        CHECK((est[k].state - ref.x).norm() < 1e-6 * ref.x.norm());
        CHECK((est[k].covariance - ref.P).norm() < 1e-5 * ref.P.norm());
        CHECK(est[k].innovation.size() == (rr ? 4 : 3));
      }
      const auto& last = est.back();
      CHECK(last.enu(0) == last.state(0));
      CHECK(last.enu(3) == last.state(1));
      CHECK(symmetric_pd(last.covariance));
    }
}

// CV EKF is consistent over 200 Monte Carlo runs (NEES at the last step, NIS over all steps)
TEST_CASE("CV EKF is consistent over 200 Monte Carlo runs") {
  const int runs = 200, steps = 40;
  const double T = 0.5, q = 1.0;
  const Eigen::Matrix2d Qa = ConstantVelocity::axis_noise_continuous(T, q);
  for (bool rr : {false, true}) {
    double nees_sum = 0, nis_sum = 0;
    int nis_count = 0, nis_dof = 0;
    const auto c = rr ? AzimuthConvention::XCounterClockwise : AzimuthConvention::NorthClockwise;
    for (int r = 0; r < runs; ++r) {
      Run run("{ q: 1 m2/s3 }", r);
      Rng rng(derive_seed(17, r, rr ? "rr" : "no-rr"));
      Eigen::Vector2d axes[3] = {{8e3, -60}, {6e3, 90}, {1.5e3, 5}};  // [p, v] per axis, 10 km range
      for (int k = 0; k < steps; ++k) {
        const Vec3 p(axes[0](0), axes[1](0), axes[2](0)), v(axes[0](1), axes[1](1), axes[2](1));
        const Estimate& e = run.feed(radar(k * T, p, v, Vec3::Zero(), RadarNoise{}, &rng, rr, c));
        if (e.updated) {
          nis_sum += e.nis;
          nis_dof += static_cast<int>(e.innovation.size());
          ++nis_count;
        }
        if (k == steps - 1) nees_sum += nees(e, p, v);
        for (auto& ax : axes) ax = (Eigen::Matrix2d() << 1, T, 0, 1).finished() * ax;
        add_process_noise<2>(Qa, axes, rng);
      }
    }
    const double anees = nees_sum / (6.0 * runs), anis = nis_sum / nis_dof;
    const auto [lo, hi] = chi2_band(6.0 * runs);
    const auto [nlo, nhi] = chi2_band(nis_dof);
    INFO("range rate " << rr << ": ANEES " << anees << " in [" << lo << ", " << hi << "], ANIS " << anis << " in ["
                       << nlo << ", " << nhi << "] over " << nis_count << " updates");
    CHECK(anees > lo);
    CHECK(anees < hi);
    CHECK(anis > nlo);
    CHECK(anis < nhi);
  }
}

TEST_CASE("Singer EKF is consistent on a Singer target over 150 runs") {
  const int runs = 150, steps = 60;
  const double T = 0.1, alpha = 0.5, sigma_m = 3.0;
  SingerModel truth_model;
  truth_model.alpha = alpha;
  truth_model.sigma = sigma_m;
  const Eigen::Matrix3d F = truth_model.axis_transition(T), Qa = truth_model.axis_noise(T);
  double nees_sum = 0;
  for (int r = 0; r < runs; ++r) {
    Run run("{ motion: singer, singer_alpha: 0.5 1/s, singer_sigma: 3 m/s2 }", r);
    Rng rng(derive_seed(23, r, "singer"));
    Eigen::Vector3d axes[3] = {{-7e3, 150, 0}, {5e3, -100, 0}, {2e3, 0, 0}};
    for (auto& ax : axes) ax(2) = sigma_m * rng.normal();  // stationary acceleration
    for (int k = 0; k < steps; ++k) {
      const Vec3 p(axes[0](0), axes[1](0), axes[2](0)), v(axes[0](1), axes[1](1), axes[2](1));
      const Estimate& e = run.feed(radar(k * T, p, v, Vec3::Zero(), RadarNoise{}, &rng, true));
      if (k == steps - 1) {
        REQUIRE(e.state.size() == 9);
        Eigen::Matrix<double, 9, 1> err;
        for (int a = 0; a < 3; ++a) err.segment<3>(3 * a) = e.state.segment<3>(3 * a) - axes[a];
        nees_sum += err.dot(Eigen::MatrixXd(e.covariance).ldlt().solve(err));
      }
      for (auto& ax : axes) ax = F * ax;
      add_process_noise<3>(Qa, axes, rng);
    }
  }
  const double anees = nees_sum / (9.0 * runs);
  const auto [lo, hi] = chi2_band(9.0 * runs);
  INFO("ANEES " << anees << " band [" << lo << ", " << hi << "]");
  CHECK(anees > lo);
  CHECK(anees < hi);
}

// CA model tracks a constantly accelerating target, initialised by two_point or paper000
TEST_CASE("CA model tracks an accelerating target") {
  for (const char* init : {"two_point", "paper000"}) {
    INFO("init " << init);
    Run run(std::string("{ motion: constant_acceleration, q_jerk: 0.01 m2/s5, init: ") + init + " }");
    Rng rng(3);
    const Vec3 p0(-4e3, 8e3, 1e3), v0(150, -50, 20), a(12, 6, -3);
    const double T = 0.05;
    RadarNoise noise;
    noise.range = 3;
    noise.azimuth = noise.elevation = 0.5e-3;
    Vec3 p, v;
    for (int k = 0; k < 400; ++k) {
      const double t = k * T;
      p = p0 + v0 * t + 0.5 * a * t * t;
      v = v0 + a * t;
      run.feed(radar(t, p, v, Vec3(0, 0, 5), noise, &rng, true));
    }
    const Estimate& e = run.out.estimates.back();
    REQUIRE(e.state.size() == 9);
    CHECK(e.updated);
    CHECK(symmetric_pd(e.covariance));
    for (int ax = 0; ax < 3; ++ax) {
      const double err = e.state(3 * ax + 2) - a(ax), sd = std::sqrt(e.covariance(3 * ax + 2, 3 * ax + 2));
      CHECK(std::abs(err) < 4 * sd);
      CHECK(std::abs(err) < 1.0);
    }
    CHECK(nees(e, p, v) < 30.0);  // chi2(6) exceeds 22.5 with probability 1e-3
  }
}

// paper000 init: state from finite differences of converted positions, per-axis P0 from sigma and T
TEST_CASE("paper000 init: finite-difference state and per-axis P0") {
  Run run("{ motion: constant_acceleration, init: paper000 }");
  const double T = 0.025;
  Vec3 z[3];
  double s2[3] = {};
  for (int k = 0; k < 3; ++k) {
    const Vec3 p = Vec3(3e3 + 200 * k * T, 4e3, 1e3 + 5 * k * T * k * T);
    const Measurement m = radar(k * T, p, Vec3::Zero(), Vec3::Zero(), RadarNoise{}, nullptr, false);
    z[k] = spherical_to_enu(m.value(0), m.value(1), m.value(2), m.azimuth);
    if (k == 2) {
      const Mat3 J = spherical_to_enu_jacobian(m.value(0), m.value(1), m.value(2), m.azimuth);
      const Mat3 Rc = J * m.covariance.topLeftCorner(3, 3) * J.transpose();
      for (int a = 0; a < 3; ++a) s2[a] = Rc(a, a);
    }
    run.feed(m);
    CHECK(run.out.estimates.back().initialised == (k == 2));
  }
  const Estimate& e = run.out.estimates.back();
  for (int a = 0; a < 3; ++a) {
    CHECK(e.state(3 * a) == Approx(z[2](a)));
    CHECK(e.state(3 * a + 1) == Approx((z[2](a) - z[1](a)) / T));
    CHECK(e.state(3 * a + 2) == Approx((z[2](a) - 2 * z[1](a) + z[0](a)) / (T * T)).margin(1e-6));
    const double s = s2[a];
    Eigen::Matrix3d expected;
    expected << s, s / T, s / (T * T), s / T, 2 * s / (T * T), 3 * s / (T * T * T), s / (T * T), 3 * s / (T * T * T),
        6 * s / std::pow(T, 4);
    CHECK((e.covariance.block(3 * a, 3 * a, 3, 3) - expected).norm() < 1e-9 * expected.norm());
  }
  CHECK(e.covariance(0, 3) == 0.0);  // no cross-axis terms in paper 000's P0
  CHECK(symmetric_pd(e.covariance));
}

TEST_CASE("range rate lowers the velocity error") {
  const int runs = 40, steps = 60;
  const double T = 0.25;
  RadarNoise noise;  // range noise dominates: 20 m against 0.3 mrad x 19 km = 6 m cross-range
  noise.range = 20;
  noise.azimuth = noise.elevation = 0.3e-3;
  double sq_use = 0, sq_ignore = 0, sq_radial_use = 0, sq_radial_ignore = 0;
  for (int r = 0; r < runs; ++r) {
    Run use("{ range_rate: use }", r), ignore("{ range_rate: ignore }", r);
    Rng rng(derive_seed(5, r, "rr"));
    const Vec3 p0(12e3, 15e3, 3e3), v(-180, -200, -10);  // mostly inbound
    for (int k = 0; k < steps; ++k) {
      const Vec3 p = p0 + v * (k * T), los = p.normalized();
      const Measurement m = radar(k * T, p, v, Vec3::Zero(), noise, &rng, true);
      const Estimate& eu = use.feed(m);
      const Estimate& ei = ignore.feed(m);
      if (k >= 10) {
        sq_use += (eu.enu.tail<3>() - v).squaredNorm();
        sq_ignore += (ei.enu.tail<3>() - v).squaredNorm();
        sq_radial_use += std::pow(los.dot(eu.enu.tail<3>() - v), 2);
        sq_radial_ignore += std::pow(los.dot(ei.enu.tail<3>() - v), 2);
      }
    }
    CHECK(ignore.out.estimates.back().innovation.size() == 3);
    CHECK(use.out.estimates.back().innovation.size() == 4);
  }
  const double n = runs * (steps - 10);
  const double rmse_use = std::sqrt(sq_use / n), rmse_ignore = std::sqrt(sq_ignore / n);
  const double radial_use = std::sqrt(sq_radial_use / n), radial_ignore = std::sqrt(sq_radial_ignore / n);
  INFO("velocity RMSE with range rate " << rmse_use << " m/s (radial " << radial_use << "), without " << rmse_ignore
                                        << " m/s (radial " << radial_ignore << ")");
  CHECK(rmse_use < rmse_ignore);
  // The radial component is measured to 0.5 m/s instead of being differenced from 20 m ranges.
  CHECK(radial_use < 0.5 * radial_ignore);
}

// an invalid measurement makes the filter coast: prediction only, covariance grows
TEST_CASE("an invalid measurement makes the filter coast") {
  Run run("{}");
  const Vec3 v(100, 0, 0);
  for (int k = 0; k < 6; ++k) run.feed(radar(k, Vec3(5e3 + 100.0 * k, 5e3, 500), v, Vec3::Zero(), RadarNoise{}, nullptr, false));
  Measurement bad = radar(6, Vec3(1e9, 1e9, 1e9), v, Vec3::Zero(), RadarNoise{}, nullptr, false);
  bad.valid = false;
  const Estimate& coast = run.feed(bad);
  REQUIRE(run.out.estimates.size() == 7);
  CHECK_FALSE(coast.updated);
  CHECK(coast.initialised);
  CHECK(coast.innovation.size() == 0);
  CHECK(coast.time == 6.0);
  CHECK(coast.enu(0) == Approx(5600).epsilon(1e-3));
  CHECK(coast.enu_covariance(0, 0) > run.out.estimates[5].enu_covariance(0, 0));
  // a non-finite value is treated like an invalid one, with a warning
  Measurement nan = radar(7, Vec3(5700, 5e3, 500), v, Vec3::Zero(), RadarNoise{}, nullptr, false);
  nan.value(1) = std::numeric_limits<double>::quiet_NaN();
  const Estimate& coast2 = run.feed(nan);
  CHECK_FALSE(coast2.updated);
  CHECK(coast2.state.allFinite());
  CHECK(run.diag.warnings.size() == 1);
  // an invalid measurement need not carry a well-formed value
  Measurement empty;
  empty.time = 8;
  empty.valid = false;
  const Estimate& coast3 = run.feed(empty);
  CHECK_FALSE(coast3.updated);
  CHECK(coast3.time == 8.0);
}

TEST_CASE("a measurement older than the track is skipped and counted") {
  Run run("{}");
  for (int k = 0; k < 3; ++k) run.feed(radar(k, Vec3(5e3 + 100.0 * k, 5e3, 500), Vec3(100, 0, 0), Vec3::Zero(), RadarNoise{}, nullptr, false));
  run.filter->on_measurement(radar(1.5, Vec3(5150, 5e3, 500), Vec3(100, 0, 0), Vec3::Zero(), RadarNoise{}, nullptr, false), 0);
  CHECK(run.out.estimates.size() == 3);
  REQUIRE(run.diag.skips.size() == 1);
  CHECK(run.diag.skips[0].node == "ekf");
}

// a target passing due south (north_clockwise) or due west (x_counterclockwise) gives no 2 pi innovation
TEST_CASE("crossing the azimuth cut gives no 2 pi innovation") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    Run run("{ q: 1 m2/s3 }");
    Rng rng(9);
    const bool nc = c == AzimuthConvention::NorthClockwise;
    // Crosses the azimuth branch cut (az = +-pi) at t = 10 s.
    const Vec3 v = nc ? Vec3(200, 0, 0) : Vec3(0, 200, 0);
    const Vec3 p0 = nc ? Vec3(-2e3, -20e3, 1e3) : Vec3(-20e3, -2e3, 1e3);
    int crossings = 0;
    double prev_az = 0;
    for (int k = 0; k < 200; ++k) {
      const double t = 0.1 * k;
      const Measurement m = radar(t, p0 + v * t, v, Vec3::Zero(), RadarNoise{}, &rng, false, c);
      if (k > 0 && std::abs(m.value(1) - prev_az) > std::numbers::pi) ++crossings;
      prev_az = m.value(1);
      const Estimate& e = run.feed(m);
      if (e.updated) {
        CHECK(std::abs(e.innovation(1)) < 6 * std::sqrt(e.innovation_covariance(1, 1)));
        CHECK(e.nis < 40.0);
      }
    }
    CHECK(crossings >= 1);  // the measured azimuth did jump by 2 pi
    const Estimate& e = run.out.estimates.back();
    CHECK(nees(e, p0 + v * 19.9, v) < 30.0);
  }
}

// a pass straight over the radar stays finite with a symmetric positive-definite covariance
TEST_CASE("a pass straight overhead stays finite and PD") {
  for (double offset : {0.0, 0.3, 3.0, 30.0}) {
    INFO("horizontal miss distance " << offset << " m");
    Run run("{ motion: constant_acceleration, q_jerk: 1 m2/s5 }");
    Rng rng(31);
    RadarNoise noise;
    noise.range = 5;
    const Vec3 v(150, 0, 0), p0(-3e3, offset, 1.5e3);  // overhead at t = 20 s
    double worst_err = 0, worst_nees = 0;
    for (int k = 0; k < 800; ++k) {
      const double t = 0.05 * k;
      const Vec3 p = p0 + v * t;
      const Estimate& e = run.feed(radar(t, p, v, Vec3::Zero(), noise, &rng, true));
      REQUIRE(e.state.allFinite());
      REQUIRE(e.enu_covariance.allFinite());
      if (e.initialised) REQUIRE(symmetric_pd(e.covariance));
      if (t > 18 && t < 22) {  // the pass: elevation above 82 deg
        worst_err = std::max(worst_err, (e.enu.head<3>() - p).norm());
        worst_nees = std::max(worst_nees, nees(e, p, v));
      }
    }
    INFO("worst position error " << worst_err << " m, worst NEES " << worst_nees << ", warnings "
                                 << run.diag.warnings.size());
    // 1 mrad at 1.5 km is 1.5 m cross-range, 5 m in range; a lost azimuth would leave tens of metres.
    CHECK(worst_err < 10.0);
    CHECK(worst_nees < 40.0);
    // The azimuth is dropped only where the horizontal range is below its uncertainty.
    CHECK(run.diag.warnings.size() == (offset < 1.0 ? 1u : 0u));
    const Estimate& e = run.out.estimates.back();
    CHECK(nees(e, p0 + v * 39.95, v) < 30.0);  // recovered after the pass
  }
}

TEST_CASE("explicit initial state: first measurement updates") {
  Run run("{ init: explicit, initial_position: [5 km, 5 km, 500 m], initial_velocity: [100, 0, 0], "
          "initial_sigma_position: 100 m, initial_sigma_velocity: 50 m/s }");
  const Estimate& e = run.feed(radar(3.0, Vec3(5e3, 5e3, 500), Vec3(100, 0, 0), Vec3::Zero(), RadarNoise{}, nullptr, false));
  CHECK(e.initialised);
  CHECK(e.updated);
  CHECK(e.time == 3.0);
  CHECK(e.enu_covariance(0, 0) < 100.0 * 100.0);
}

// noise handles: R in spherical space, per-axis q that the prediction follows
TEST_CASE("noise handles: spherical R and per-axis q") {
  auto make = [] { return Run("{ q: 1 m2/s3 }"); };
  Run a = make(), b = make();
  auto* fa = dynamic_cast<Filter*>(a.filter.get());
  auto* fb = dynamic_cast<Filter*>(b.filter.get());
  REQUIRE(fa);
  const NoiseHandles h = fb->noise();
  CHECK(h.measurement.space == MeasurementSpace::Spherical);
  REQUIRE(h.process.count == 3);
  CHECK(fa->noise().process.values[0] == 1.0);
  for (int k = 0; k < 5; ++k) {
    if (k == 3) h.process.values[0] = 100.0;  // an adapter raising q east after the first steps
    const Measurement m = radar(k, Vec3(5e3 + 100.0 * k, 5e3, 500), Vec3(100, 0, 0), Vec3::Zero(), RadarNoise{}, nullptr, false);
    a.feed(m);
    b.feed(m);
  }
  CHECK(b.out.estimates.back().enu_covariance(3, 3) > 2 * a.out.estimates.back().enu_covariance(3, 3));
}

TEST_CASE("wrong inputs and parameters are clear errors") {
  Run run("{}");
  Measurement m = radar(0, Vec3(1e3, 2e3, 3e2), Vec3::Zero(), Vec3::Zero(), RadarNoise{}, nullptr, false);
  m.frame = Frame::Cartesian;
  CHECK_THROWS_WITH(run.filter->on_measurement(m, 0), Catch::Contains("filter.kalman") && Catch::Contains("node 'ekf'"));
  Run use("{ range_rate: use }");
  m.frame = Frame::Spherical;
  CHECK_THROWS_WITH(use.filter->on_measurement(m, 0), Catch::Contains("no range rate"));
  m.has_range_rate = true;  // flag without the 4th value
  CHECK_THROWS_AS(run.filter->on_measurement(m, 0), DataError);

  auto error = [](const std::string& params) {
    try {
      test::make("filter.ekf", params);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(error("{ motion: constant_acceleration, q: 1 m2/s3 }"), Catch::Contains("q_jerk"));
  CHECK_THAT(error("{ q_jerk: 1 m2/s5 }"), Catch::Contains("constant_acceleration"));
  CHECK_THAT(error("{ motion: singer, singer_alpha: 1 1/s }"), Catch::Contains("required"));
  CHECK_THAT(error("{ motion: singer, singer_sigma: 1 m/s2 }"), Catch::Contains("required"));
  CHECK_THAT(error("{ singer_alpha: 1 1/s }"), Catch::Contains("motion: singer"));
  CHECK_THAT(error("{ motion: singer, singer_alpha: 1 1/s, singer_sigma: 2 m/s2, sigma_accel: 1 m/s2 }"),
             Catch::Contains("singer_sigma"));
  CHECK_THAT(error("{ q: 1 m2/s3, sigma_accel: 1 m/s2 }"), Catch::Contains("not both"));
  CHECK_THAT(error("{ init: explicit }"), Catch::Contains("initial_position"));
  CHECK_THAT(error("{ initial_position: [1, 2, 3] }"), Catch::Contains("init: explicit"));
  CHECK_THAT(error("{ initial_sigma_acceleration: 1 m/s2 }"), Catch::Contains("no acceleration"));
  CHECK_THAT(error("{ motion: constant_acceleration, init: paper000, initial_sigma_acceleration: 1 m/s2 }"),
             Catch::Contains("paper000"));
  CHECK_THAT(error("{ range_rate: always }"), Catch::Contains("range_rate"));
  CHECK(error("{ motion: singer, singer_alpha: 1 1/s, singer_sigma: 2 m/s2, init: paper000 }") == "no error");
}

// A 2-D radar's polar plots of a target in its horizontal plane: the EKF agrees step by step with the
// textbook EKF on h = [r, az(, rdot)] (numerical Jacobian), its track stays in the radar's plane
// (z at the radar's height, zero z variance), and the innovation has the polar size.
TEST_CASE("2-D radar polar plots agree with a textbook EKF") {
  for (bool rr : {false, true}) {
    INFO("range rate " << rr);
    Run run("{ q: 4 m2/s3 }");
    Rng rng(33);
    const Vec3 sensor(100, -200, 15);
    const double T = 1.0;
    const double sr = 20.0, saz = 2e-3, srr = 1.0;
    std::vector<Measurement> ms;
    for (int k = 0; k < 40; ++k) {
      const double t = k * T;
      const Vec3 v(-150, 60, 0), p = Vec3(8e3, 12e3, sensor.z()) + v * t;
      Measurement m;
      m.time = t;
      m.frame = Frame::Polar;
      m.sensor_position = sensor;
      m.has_range_rate = rr;
      const int n = rr ? 3 : 2;
      m.value.resize(n);
      m.covariance = MeasCov::Zero(n, n);
      const Vec3 rae = enu_to_spherical(p - sensor, m.azimuth);
      m.value(0) = rae(0) + sr * rng.normal();
      m.value(1) = wrap_angle(rae(1) + saz * rng.normal());
      m.covariance(0, 0) = sr * sr;
      m.covariance(1, 1) = saz * saz;
      if (rr) {
        m.value(2) = range_rate(p - sensor, v) + srr * rng.normal();
        m.covariance(2, 2) = srr * srr;
      }
      ms.push_back(m);
      run.feed(m);
    }
    const auto& est = run.out.estimates;
    REQUIRE(est.size() == 40);
    REQUIRE(est[1].initialised);
    ReferenceEkf ref;
    ref.q = 4.0;
    ref.planar = true;
    ref.x = Eigen::VectorXd::Zero(6);
    ref.P = Eigen::MatrixXd::Zero(6, 6);
    Vec3 z[2];
    Mat3 R[2];
    for (int i = 0; i < 2; ++i) {  // classical conversion at elevation 0
      const auto& v = ms[i].value;
      z[i] = spherical_to_enu(v(0), v(1), 0.0, ms[i].azimuth) + sensor;
      Mat3 Rs = Mat3::Zero();
      Rs.topLeftCorner<2, 2>() = ms[i].covariance.topLeftCorner(2, 2);
      const Mat3 J = spherical_to_enu_jacobian(v(0), v(1), 0.0, ms[i].azimuth);
      R[i] = J * Rs * J.transpose();
    }
    for (int a = 0; a < 3; ++a) {
      ref.x(2 * a) = z[1](a);
      ref.x(2 * a + 1) = (z[1](a) - z[0](a)) / T;
      for (int b = 0; b < 3; ++b) {
        ref.P(2 * a, 2 * b) = R[1](a, b);
        ref.P(2 * a, 2 * b + 1) = ref.P(2 * b + 1, 2 * a) = R[1](a, b) / T;
        ref.P(2 * a + 1, 2 * b + 1) = (R[0](a, b) + R[1](a, b)) / (T * T);
      }
    }
    CHECK((est[1].state - ref.x).norm() < 1e-9 * ref.x.norm());
    for (size_t k = 2; k < ms.size(); ++k) {
      ref.predict(T);
      ref.update(ms[k]);
      CHECK(est[k].updated);
      CHECK((est[k].state - ref.x).norm() < 1e-6 * ref.x.norm());
      CHECK((est[k].covariance - ref.P).norm() < 1e-5 * ref.P.norm());
      CHECK(est[k].innovation.size() == (rr ? 3 : 2));
      CHECK(est[k].enu(2) == sensor.z());  // the track lies in the radar's horizontal plane
      CHECK(est[k].enu(5) == 0.0);
      CHECK(est[k].enu_covariance(2, 2) == 0.0);
    }
    CHECK(symmetric_pd(est.back().covariance.topLeftCorner(4, 4)));
  }
}

// filter.ukf takes no polar plots: refused with the frames it takes; a tilted 2-D radar is refused by filter.ekf.
TEST_CASE("polar plots: UKF refuses and a tilted 2-D radar is refused") {
  Measurement m;
  m.frame = Frame::Polar;
  m.value = Eigen::Vector2d(5e3, 0.3);
  m.covariance = MeasCov::Identity(2, 2);
  FilterRun ukf("filter.ukf", "{ q: 1 m2/s3 }");
  CHECK_THROWS_WITH(ukf.feed(m), Catch::Contains("takes spherical measurements") && Catch::Contains("polar"));
  Run ekf("{ q: 1 m2/s3 }");
  m.sensor_level = false;
  m.sensor_axes = Eigen::AngleAxisd(0.01, Vec3::UnitX()).toRotationMatrix();
  CHECK_THROWS_WITH(ekf.feed(m), Catch::Contains("horizontal plane"));
}
