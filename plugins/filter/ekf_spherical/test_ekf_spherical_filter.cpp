// Purpose: tests of filter.ekf_spherical through the plugin loader: consistency on a long-range CV target, both azimuth conventions, wrap, zenith, coasting, errors.
#include "spherical_ca_model.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "estimation/radar_filter_test_support.hpp"
#include "plugin_fixture.hpp"

using namespace trackflow;
namespace es = trackflow::ekf_spherical;

namespace {

constexpr double kPi = std::numbers::pi;

struct Noise {
  double r = 10.0, az = 1e-3, el = 1e-3, rdot = 0.5;
};

// A radar at `sensor` measuring the target at absolute position p with velocity v (the Cartesian
// filters' shared test helper: the same draws in the same order).
Measurement radar(double t, const Vec3& sensor, const Vec3& p, const Vec3& v, const Noise& s, bool with_rate,
                  AzimuthConvention c, Rng& rng) {
  return filter_test::radar(t, p, v, sensor, {s.r, s.az, s.el, s.rdot}, &rng, with_rate, c);
}

struct Track {
  std::shared_ptr<Component> c;
  Filter* f;
  test::Collector out;
  Diagnostics diag;
  explicit Track(const std::string& params = "{}") : c(test::make("filter.ekf_spherical", params)) {
    f = &dynamic_cast<Filter&>(*c);
    out.attach_to(*c);
    test::save_configured_noise(*f);  // as the engine does once the graph is built
  }
  void start(std::uint64_t run = 0) {
    out.estimates.clear();
    diag = Diagnostics();
    test::start_run(*c, run, 1, &diag);  // as the engine does at the start of every run
  }
};

bool symmetric_psd(const StateCov& P) {
  if ((P - P.transpose()).norm() > 1e-12 * P.norm()) return false;
  const Eigen::VectorXd sd = P.diagonal().cwiseSqrt();
  if (!(sd.array() > 0).all()) return false;
  const Eigen::MatrixXd C = sd.cwiseInverse().asDiagonal() * P * sd.cwiseInverse().asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C).eigenvalues().minCoeff() > -1e-9;
}

// The same filter structure, linear and per channel: a CA Kalman filter with white-jerk
// intensity q measuring position (sigma_p) and optionally velocity (sigma_v), run on a target
// with no process noise. Its P comes from the Riccati recursion, the actual error covariance from
// the Lyapunov recursion of e <- (I - K H) F e + K v; returns E[NEES]/2 of (position, velocity)
// in steady state. A filter whose Q covers a deterministic truth is conservative by this factor.
double deterministic_truth_anees(double T, double q, double sigma_p, double sigma_v) {
  const int m = sigma_v > 0 ? 2 : 1;
  Eigen::Matrix3d F;
  F << 1, T, T * T / 2, 0, 1, T, 0, 0, 1;
  const Eigen::Matrix3d Q = q * (Eigen::Matrix3d() << std::pow(T, 5) / 20, std::pow(T, 4) / 8, std::pow(T, 3) / 6,
                                 std::pow(T, 4) / 8, std::pow(T, 3) / 3, T * T / 2, std::pow(T, 3) / 6, T * T / 2, T)
                                    .finished();
  Eigen::MatrixXd H = Eigen::MatrixXd::Identity(m, 3), R = Eigen::MatrixXd::Zero(m, m);
  R(0, 0) = sigma_p * sigma_p;
  if (m == 2) R(1, 1) = sigma_v * sigma_v;
  Eigen::Matrix3d P = Eigen::Matrix3d::Identity() * 1e8;
  Eigen::MatrixXd K;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Matrix3d Pm = F * P * F.transpose() + Q;
    K = Pm * H.transpose() * (H * Pm * H.transpose() + R).inverse();
    P = (Eigen::Matrix3d::Identity() - K * H) * Pm;
  }
  const Eigen::Matrix3d A = (Eigen::Matrix3d::Identity() - K * H) * F;
  Eigen::Matrix3d Pa = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 20000; ++i) Pa = A * Pa * A.transpose() + K * R * K.transpose();
  return (P.topLeftCorner<2, 2>().inverse() * Pa.topLeftCorner<2, 2>()).trace() / 2;
}

}  // namespace

// long-range CV target, 200 runs: bounded ANEES and position error below the measurement error
TEST_CASE("long-range CV target: bounded ANEES and error") {
  const int runs = 200, steps = 240;
  const double T = 0.5;
  const Vec3 sensor(1000, -500, 20);
  const Noise s;  // 10 m, 1 mrad: 70 m cross-range at the track's ~70 km
  for (bool with_rate : {false, true}) {
    const double q = 0.01;
    Track k("{ q_r: 0.01 m2/s5, q_h: 0.01 m2/s5, q_v: 0.01 m2/s5, initial_sigma_acceleration: 2 m/s2 }");
    double nees_sum = 0, err2_filter = 0, err2_meas = 0;
    long nees_count = 0, err_count = 0;
    bool all_psd = true;
    for (int r = 0; r < runs; ++r) {
      k.start(r);
      Rng rng(derive_seed(5, r, "ekf_spherical"));
      const Vec3 p0 = sensor + Vec3(60e3, 40e3, 8e3), v(-250, 100, 5);
      for (int i = 0; i < steps; ++i) {
        const double t = i * T;
        const Vec3 p = p0 + v * t;
        const Measurement m = radar(t, sensor, p, v, s, with_rate, AzimuthConvention::NorthClockwise, rng);
        k.c->on_measurement(m, 0);
        const Estimate& e = k.out.estimates.back();
        if (i < 2) continue;
        all_psd = all_psd && symmetric_psd(e.covariance) && e.enu.allFinite();
        if (i >= steps / 2) {  // after the initial transient
          Vec6 err;
          err << e.enu.head<3>() - p, e.enu.tail<3>() - v;
          nees_sum += err.dot(e.enu_covariance.ldlt().solve(err));
          ++nees_count;
          err2_filter += (e.enu.head<3>() - p).squaredNorm();
          const Vec3 zp = sensor + spherical_to_enu(m.value(0), m.value(1), m.value(2), m.azimuth);
          err2_meas += (zp - p).squaredNorm();
          ++err_count;
        }
      }
    }
    const double anees = nees_sum / (6.0 * nees_count);
    const double rms_filter = std::sqrt(err2_filter / err_count), rms_meas = std::sqrt(err2_meas / err_count);
    // The truth has no process noise, so a consistent filter is conservative: its expected ANEES is
    // that of the linear analogue per channel (radial; cross-range at R_h sigma_az and R sigma_el,
    // R ~ 66 km, elevation ~ 7 deg over the second half), averaged over the three channels.
    const double Rmid = 66e3, cos_el = std::cos(7.0 * kPi / 180);
    const double expected = (deterministic_truth_anees(T, q, s.r, with_rate ? s.rdot : 0.0) +
                             deterministic_truth_anees(T, q, Rmid * cos_el * s.az, 0.0) +
                             deterministic_truth_anees(T, q, Rmid * s.el, 0.0)) / 3;
    INFO("with range rate: " << with_rate << "; ANEES " << anees << ", linear analogue " << expected
                             << "; RMS position error " << rms_filter << " m vs measurement " << rms_meas << " m");
    CHECK(all_psd);
    // Spread: NEES/6 averaged within a run varies about 0.6 * expected / sqrt(6) run to run at
    // most (one step's chi-square(6)); over 200 runs that is 0.02, so +-0.1 is 5 sigma and also
    // leaves room for the spherical model's own truncation error, which Q must cover.
    CHECK(std::abs(anees - expected) < 0.1);
    CHECK(rms_filter < 0.5 * rms_meas);
  }
}

// truth drawn from the filter's own model: ANEES and ANIS inside their chi-square bands
TEST_CASE("own-model truth: ANEES and ANIS in their bands") {
  // The truth follows f with white-jerk noise sampled from Q at the true state, and is measured
  // through the linear H: only the EKF's linearisation separates the filter from the optimum, and
  // at 60 km with 1 mrad that is negligible, so the classical bands apply.
  const int runs = 200, steps = 240;
  const double T = 0.5, q = 1e-3, sigma_a = 0.5;
  const Noise s;
  Track k("{ q_r: 1e-3 m2/s5, q_h: 1e-3 m2/s5, q_v: 1e-3 m2/s5, initial_sigma_acceleration: 0.5 m/s2 }");
  const es::Guard guard;
  const Eigen::Matrix3d Q1 = ConstantAcceleration::axis_noise_continuous(T, 1.0);
  const double qs[3] = {q, q, q};
  double nees_sum = 0, nis_sum = 0;
  long nis_count = 0;
  for (int r = 0; r < runs; ++r) {
    k.start(r);
    Rng rng(derive_seed(17, r, "matched"));
    es::State x;
    x << 60e3, -100, sigma_a * rng.normal(), 0.8, 150, sigma_a * rng.normal(), 0.12, 20, sigma_a * rng.normal();
    for (int i = 0; i < steps; ++i) {
      if (i > 0) {
        es::Matrix Q;
        es::process_noise(x, Q1, qs, guard, Q);
        const es::Matrix L = Q.llt().matrixL();
        es::State w;
        for (int j = 0; j < es::kDim; ++j) w(j) = rng.normal();
        es::propagate(x, T, guard);
        x += L * w;
        x(es::kTheta) = wrap_angle(x(es::kTheta));
      }
      Measurement m;
      m.time = i * T;
      m.value.resize(3);
      m.value << x(es::kR) + s.r * rng.normal(), wrap_angle(x(es::kTheta) + s.az * rng.normal()),
          x(es::kPhi) + s.el * rng.normal();
      m.covariance = MeasCov::Zero(3, 3);
      m.covariance.diagonal() << s.r * s.r, s.az * s.az, s.el * s.el;
      k.c->on_measurement(m, 0);
      const Estimate& e = k.out.estimates.back();
      if (i >= 2) {
        nis_sum += e.nis;
        ++nis_count;
      }
      if (i == steps - 1) {
        es::State err = e.state - x;
        err(es::kTheta) = wrap_angle(err(es::kTheta));
        // Scale-free solve: the states span 12 orders of magnitude in variance.
        const es::State sd = e.covariance.diagonal().cwiseSqrt();
        const es::Matrix C = sd.cwiseInverse().asDiagonal() * e.covariance * sd.cwiseInverse().asDiagonal();
        const es::State u = err.cwiseQuotient(sd);
        nees_sum += u.dot(C.ldlt().solve(u));
      }
    }
  }
  const double anees = nees_sum / (9.0 * runs), anis = nis_sum / (3.0 * nis_count);
  INFO("ANEES " << anees << ", ANIS " << anis);
  // chi-square(9 * 200) / 1800, 99 %: [0.916, 1.088] (Wilson-Hilferty).
  CHECK(anees > 0.916);
  CHECK(anees < 1.088);
  // Innovations of a consistent filter are white: chi-square(3 * 47600) / 142800, 99 %: +-0.0097.
  CHECK(std::abs(anis - 1.0) < 0.0097);
}

// the same data in both azimuth conventions give the same ENU estimate; v_h changes sign
TEST_CASE("both azimuth conventions give the same estimate") {
  Track cw, ccw;
  cw.start();
  ccw.start();
  Rng rng(3);
  const Vec3 sensor(-200, 300, 10), v(180, -60, 20);
  const Vec3 p0 = sensor + Vec3(-15e3, 25e3, 4e3);
  for (int i = 0; i < 120; ++i) {
    const double t = 0.25 * i;
    const Vec3 p = p0 + v * t;
    Measurement m = radar(t, sensor, p, v, Noise{}, true, AzimuthConvention::NorthClockwise, rng);
    cw.c->on_measurement(m, 0);
    m.azimuth = AzimuthConvention::XCounterClockwise;  // the same measured direction, other reference
    m.value(1) = wrap_angle(kPi / 2 - m.value(1));
    ccw.c->on_measurement(m, 0);
  }
  REQUIRE(cw.out.estimates.size() == 120);
  for (size_t i = 1; i < cw.out.estimates.size(); ++i) {
    const Estimate &a = cw.out.estimates[i], &b = ccw.out.estimates[i];
    REQUIRE(a.initialised);
    CHECK((a.enu - b.enu).norm() < 1e-6 * a.enu.norm());
    CHECK((a.enu_covariance - b.enu_covariance).norm() < 1e-6 * a.enu_covariance.norm());
    CHECK(b.state(es::kVh) == Approx(-a.state(es::kVh)).epsilon(1e-6).margin(1e-6));
    CHECK(b.state(es::kTheta) == Approx(wrap_angle(kPi / 2 - a.state(es::kTheta))).margin(1e-9));
    // ENU position = sensor + the point (R, θ, φ) names (geometry.hpp, independent of the filter).
    const Vec3 pa = sensor + spherical_to_enu(a.state(es::kR), a.state(es::kTheta), a.state(es::kPhi),
                                              AzimuthConvention::NorthClockwise);
    CHECK((a.enu.head<3>() - pa).norm() < 1e-9 * pa.norm());
    // Its covariance block is the position Jacobian (geometry.hpp) applied to the (R, θ, φ) block.
    const Mat3 Jp = spherical_to_enu_jacobian(a.state(es::kR), a.state(es::kTheta), a.state(es::kPhi),
                                              AzimuthConvention::NorthClockwise);
    const int idx[3] = {es::kR, es::kTheta, es::kPhi};
    Mat3 Psph;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Psph(r, c) = a.covariance(idx[r], idx[c]);
    const Mat3 Cp = Jp * Psph * Jp.transpose();
    CHECK((a.enu_covariance.topLeftCorner<3, 3>() - Cp).norm() < 1e-9 * Cp.norm());
  }
  const Estimate& last = cw.out.estimates.back();
  CHECK((last.enu.head<3>() - (p0 + v * 0.25 * 119)).norm() < 30.0);
  CHECK((last.enu.tail<3>() - v).norm() < 10.0);
}

// azimuth crossing ±pi: no jump in the innovation, estimate stays on the target
TEST_CASE("azimuth crossing pi gives no innovation jump") {
  // north_clockwise: south of the sensor moving west (bearing 180 deg); x_counterclockwise: west
  // of the sensor moving south (math angle 180 deg).
  struct Case {
    AzimuthConvention c;
    Vec3 d0, v;
  };
  for (const Case& cs : {Case{AzimuthConvention::NorthClockwise, Vec3(3e3, -20e3, 2e3), Vec3(-200, 0, 0)},
                         Case{AzimuthConvention::XCounterClockwise, Vec3(-20e3, 3e3, 2e3), Vec3(0, -200, 0)}}) {
    Track k;
    k.start();
    Rng rng(9);
    double max_nis = 0, max_err = 0;
    for (int i = 0; i < 200; ++i) {
      const double t = 0.2 * i;
      const Vec3 p = cs.d0 + cs.v * t;
      k.c->on_measurement(radar(t, Vec3::Zero(), p, cs.v, Noise{}, false, cs.c, rng), 0);
      const Estimate& e = k.out.estimates.back();
      if (i < 20) continue;
      REQUIRE(e.updated);
      CHECK(e.state(es::kTheta) > -kPi);
      CHECK(e.state(es::kTheta) <= kPi);
      CHECK(std::abs(e.innovation(1)) < 6 * std::sqrt(e.innovation_covariance(1, 1)));
      max_nis = std::max(max_nis, e.nis);
      max_err = std::max(max_err, (e.enu.head<3>() - p).norm());
    }
    // The crossing happened: bearing went from one side of ±pi to the other.
    const double th_first = k.out.estimates[20].state(es::kTheta), th_last = k.out.estimates.back().state(es::kTheta);
    CHECK(th_first * th_last < 0);
    CHECK(std::abs(th_first) > 2.5);
    CHECK(max_nis < 25.0);  // chi-square(3) exceeds 25 with probability 2e-5 per step
    CHECK(max_err < 60.0);
  }
}

// passes near the zenith stay finite and recover; straight overhead the track holds
TEST_CASE("passes near and over the zenith stay finite") {
  // 250 m/s at 3 km altitude, 20 Hz, overhead (or `miss` metres to the side) at t = 32 s.
  for (double miss : {0.0, 3.0, 30.0}) {
    INFO("miss distance " << miss << " m");
    Track k("{ q_r: 100 m2/s5, q_h: 100 m2/s5, q_v: 100 m2/s5 }");
    k.start();
    Rng rng(4);
    const Vec3 v(250, 0, 0), p0(-8e3, miss, 3e3);
    double max_err = 0, max_err_after = 0;
    for (int i = 0; i < 1280; ++i) {
      const double t = 0.05 * i;
      const Vec3 p = p0 + v * t;
      k.c->on_measurement(radar(t, Vec3::Zero(), p, v, Noise{5.0, 1e-3, 1e-3, 0.5}, false,
                                AzimuthConvention::NorthClockwise, rng), 0);
      const Estimate& e = k.out.estimates.back();
      REQUIRE(e.state.allFinite());
      REQUIRE(e.covariance.allFinite());
      REQUIRE(e.enu.allFinite());
      REQUIRE(e.enu_covariance.allFinite());
      if (i < 40) continue;
      REQUIRE(symmetric_psd(e.covariance));
      REQUIRE(std::abs(e.state(es::kPhi)) <= kPi / 2);  // folded back over the top
      const double err = (e.enu.head<3>() - p).norm();
      max_err = std::max(max_err, err);
      if (t >= 42.0) max_err_after = std::max(max_err_after, err);
    }
    k.c->end_run();
    auto warned = [&](const char* what) {
      for (const auto& w : k.diag.warnings)
        if (w.message.find(what) != std::string::npos) return true;
      return false;
    };
    CHECK(warned("guard"));
    INFO("max position error " << max_err << " m, after t = 42 s " << max_err_after << " m");
    CHECK(max_err_after < 30.0);  // tracking again from the far side, azimuth near +pi/2
    CHECK(std::abs(k.out.estimates.back().state(es::kTheta) - kPi / 2) < 0.05);
    if (miss == 0.0) {
      // Straight overhead the azimuth is dropped, the state folds over the top, and the track holds.
      CHECK(warned("azimuth not used"));
      CHECK(max_err < 30.0);
    }
  }
}

TEST_CASE("an invalid measurement makes the filter coast") {
  Track k;
  k.start();
  Rng rng(1);
  const Vec3 v(100, 50, 0), p0(20e3, 20e3, 3e3);
  for (int i = 0; i < 20; ++i) k.c->on_measurement(radar(i, Vec3::Zero(), p0 + v * i, v, Noise{}, false,
                                                         AzimuthConvention::NorthClockwise, rng), 0);
  Measurement bad = radar(20, Vec3::Zero(), p0 + v * 20, v, Noise{}, false, AzimuthConvention::NorthClockwise, rng);
  bad.valid = false;
  bad.value(0) = 1e9;
  k.c->on_measurement(bad, 0);
  REQUIRE(k.out.estimates.size() == 21);
  const Estimate& coast = k.out.estimates.back();
  CHECK_FALSE(coast.updated);
  CHECK(coast.initialised);
  CHECK(coast.innovation.size() == 0);
  CHECK((coast.enu.head<3>() - (p0 + v * 20)).norm() < 60.0);
  CHECK(coast.covariance(es::kR, es::kR) > k.out.estimates[19].covariance(es::kR, es::kR));
}

// range rate is used when present and improves the radial velocity
TEST_CASE("range rate improves the radial velocity") {
  double err_with = 0, err_without = 0;
  for (bool with_rate : {false, true}) {
    Track k;
    double err2 = 0;
    for (int r = 0; r < 30; ++r) {
      k.start(r);
      Rng rng(derive_seed(8, r, "rr"));
      const Vec3 v(-150, 80, 10), p0(30e3, 10e3, 5e3);
      for (int i = 0; i < 100; ++i) {
        const Vec3 p = p0 + v * (0.2 * i);
        k.c->on_measurement(radar(0.2 * i, Vec3::Zero(), p, v, Noise{}, with_rate, AzimuthConvention::NorthClockwise,
                                  rng), 0);
      }
      const Estimate& e = k.out.estimates.back();
      const Vec3 p = p0 + v * 19.8;
      CHECK(e.innovation.size() == (with_rate ? 4 : 3));
      err2 += std::pow(e.state(es::kVr) - range_rate(p, v), 2);
    }
    (with_rate ? err_with : err_without) = std::sqrt(err2 / 30);
  }
  INFO("radial velocity RMS error with rdot " << err_with << ", without " << err_without);
  CHECK(err_with < 0.5 * err_without);
}

// noise handles: spherical R, three jerk intensities, and a change takes effect
TEST_CASE("noise handles: spherical R and jerk intensities") {
  auto run = [](double qh_after) {
    Track k;
    k.start();
    const NoiseHandles h = k.f->noise();
    CHECK(h.process.count == 3);
    CHECK(h.measurement.space == MeasurementSpace::Spherical);
    Rng rng(2);
    const Vec3 v(100, 0, 0), p0(0, 30e3, 2e3);
    for (int i = 0; i < 20; ++i)
      k.c->on_measurement(radar(i, Vec3::Zero(), p0 + v * i, v, Noise{}, false, AzimuthConvention::NorthClockwise,
                                rng), 0);
    CHECK(h.measurement.R->rows() == 3);
    h.process.values[1] = qh_after;
    k.c->on_measurement(radar(20, Vec3::Zero(), p0 + v * 20, v, Noise{}, false, AzimuthConvention::NorthClockwise,
                              rng), 0);
    const double var_ah = k.out.estimates.back().covariance(es::kAh, es::kAh);
    k.start(1);  // the next run starts from the configured q whatever an adapter left
    CHECK(h.process.values[1] == 1.0);
    return var_ah;
  };
  CHECK(run(100.0) > 2 * run(1.0));
}

// explicit initialisation holds at the first measurement's time
TEST_CASE("explicit initialisation holds at the first time") {
  Track k("{ init: explicit, initial_range: 20 km, initial_azimuth: 30 deg, initial_elevation: 5 deg, "
          "initial_velocity: [0, 100, 0], initial_sigma_range: 50 m, initial_sigma_angle: 5 mrad, "
          "initial_sigma_velocity: 50 m/s }");
  k.start();
  Rng rng(6);
  const double az = 30 * kPi / 180, el = 5 * kPi / 180;
  const Vec3 p0 = spherical_to_enu(20e3, az, el, AzimuthConvention::NorthClockwise);
  const Vec3 v = 100 * Vec3(std::cos(az), -std::sin(az), 0);  // e_theta
  for (int i = 0; i < 3; ++i)
    k.c->on_measurement(radar(100.0 + i, Vec3::Zero(), p0 + v * i, v, Noise{}, false,
                              AzimuthConvention::NorthClockwise, rng), 0);
  REQUIRE(k.out.estimates.size() == 3);
  for (const auto& e : k.out.estimates) {
    CHECK(e.initialised);
    CHECK(e.updated);
    CHECK(e.state.allFinite());
  }
  const Estimate& e = k.out.estimates.back();
  const Vec3 err = e.enu.head<3>() - (p0 + 2 * v);
  CHECK(err.dot(e.enu_covariance.topLeftCorner<3, 3>().ldlt().solve(err)) < 16.3);  // chi-square(3), 99.9 %
}

// two-point start: first estimate uninitialised (zeros), second initialised
TEST_CASE("two-point start initialises at the second") {
  Track k;
  k.start();
  Rng rng(6);
  const Vec3 v(100, 0, 0), p0(0, 30e3, 2e3);
  for (int i = 0; i < 2; ++i)
    k.c->on_measurement(radar(i, Vec3::Zero(), p0 + v * i, v, Noise{}, false, AzimuthConvention::NorthClockwise, rng),
                        0);
  REQUIRE(k.out.estimates.size() == 2);
  CHECK_FALSE(k.out.estimates[0].initialised);
  CHECK(k.out.estimates[0].state.size() == 9);
  CHECK(k.out.estimates[0].state.isZero());
  CHECK(k.out.estimates[1].initialised);
  CHECK(k.out.estimates[1].state(es::kAr) == 0.0);
  CHECK(k.out.estimates[1].covariance(es::kAr, es::kAr) == Approx(50.0 * 50.0));
}

TEST_CASE("wrong inputs and parameters are clear errors") {
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical", "{ init: explicit }"), Catch::Contains("initial_range"));
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical", "{ initial_range: 3 km }"), Catch::Contains("init: explicit"));
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical", "{ q_h: 1 urad }"), Catch::Contains("q_h"));
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical", "{ q_r: -1 m2/s5 }"), Catch::Contains("q_r"));
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical", "{ max_elevation: 95 deg }"), Catch::Contains("max_elevation"));
  CHECK_THROWS_WITH(test::make("filter.ekf_spherical",
                               "{ init: explicit, initial_range: 20 km, initial_azimuth: 0 deg, initial_elevation: "
                               "89.5 deg, initial_sigma_range: 5 m, initial_sigma_angle: 1 mrad, "
                               "initial_sigma_velocity: 10 m/s }"),
                    Catch::Contains("max_elevation"));

  Track k;
  k.start();
  Rng rng(1);
  Measurement m = radar(0, Vec3::Zero(), Vec3(1e4, 1e4, 1e3), Vec3::Zero(), Noise{}, false,
                        AzimuthConvention::NorthClockwise, rng);
  Measurement cart = m;
  cart.frame = Frame::Cartesian;
  CHECK_THROWS_WITH(k.c->on_measurement(cart, 0), Catch::Contains("filter.kalman"));
  k.c->on_measurement(m, 0);
  Measurement other = m;
  other.time = 1;
  other.azimuth = AzimuthConvention::XCounterClockwise;
  CHECK_THROWS_WITH(k.c->on_measurement(other, 0), Catch::Contains("azimuth convention"));
  other.azimuth = AzimuthConvention::NorthClockwise;
  other.sensor_position = Vec3(100, 0, 0);
  CHECK_THROWS_WITH(k.c->on_measurement(other, 0), Catch::Contains("sensor position"));
  Measurement short_cov = m;
  short_cov.time = 1;
  short_cov.covariance = MeasCov::Identity(2, 2);
  CHECK_THROWS_WITH(k.c->on_measurement(short_cov, 0), Catch::Contains("expected 3"));

  Track use("{ range_rate: use }");
  use.start();
  CHECK_THROWS_WITH(use.c->on_measurement(m, 0), Catch::Contains("range_rate: use"));
}
