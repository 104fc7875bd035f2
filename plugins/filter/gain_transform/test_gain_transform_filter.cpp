// Purpose: tests of filter.gain_transform through the plugin loader: gain vs filter.ekf's in paper 002's geometry, Monte Carlo consistency, PSD covariance, azimuth wrap, zenith, coasting, noise handles, errors.
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "estimation/radar_filter_test_support.hpp"
#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

constexpr double kRate = 40.0, kT = 1.0 / kRate;  // paper 002: 40 Hz
constexpr double kSigmaRange = 15.0, kSigmaAngle = 3e-3;
const char* const kGt = "{ singer_alpha: 1 1/s, singer_sigma: 20 m/s2 }";
const char* const kEkf = "{ motion: singer, singer_alpha: 1 1/s, singer_sigma: 20 m/s2 }";

// A radar measurement built with geometry.hpp only (the Cartesian filters' shared test helper).
Measurement radar(double t, const Vec3& pos, const Vec3& sensor, Rng* rng,
                  AzimuthConvention c = AzimuthConvention::NorthClockwise, bool with_rr = false,
                  const Vec3& vel = Vec3::Zero()) {
  return filter_test::radar(t, pos, vel, sensor, {kSigmaRange, kSigmaAngle, kSigmaAngle, 1.0}, rng, with_rr, c);
}

// Paper 002 scenario (1): circle of 1500 m radius at 150 m altitude, 200 m/s, radar at its centre.
Vec3 circle_position(double t) {
  const double w = 200.0 / 1500.0;
  return {1500.0 * std::cos(w * t), 1500.0 * std::sin(w * t), 150.0};
}
std::vector<Measurement> circle_measurements(int steps, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Measurement> ms;
  for (int k = 0; k < steps; ++k) ms.push_back(radar(k * kT, circle_position(k * kT), Vec3::Zero(), &rng));
  return ms;
}

struct Run {
  std::shared_ptr<Component> filter;
  test::Collector out;
  Diagnostics diag;
  Run(const std::string& type, const std::string& params, std::uint64_t run = 0)
      : filter(test::make(type, params, "f")) {
    out.attach_to(*filter);
    filter->start_run({run, 1, &diag});
  }
  const Estimate& feed(const Measurement& m) {
    filter->on_measurement(m, 0);
    return out.estimates.back();
  }
};

double nees(const Estimate& e, const Eigen::VectorXd& truth) {
  const Eigen::VectorXd err = Eigen::VectorXd(e.state) - truth;
  return err.dot(Eigen::MatrixXd(e.covariance).ldlt().solve(err));
}

bool symmetric_psd(const StateCov& P) {
  if (!P.allFinite()) return false;
  if ((P - P.transpose()).norm() > 1e-12 * P.norm()) return false;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(P)).eigenvalues().minCoeff() >= -1e-9 * P.norm();
}

// 99 % two-sided band of chi2(k)/k (Wilson-Hilferty).
std::pair<double, double> chi2_band(double k) {
  const double z = 2.5758, c = 2.0 / (9.0 * k);
  return {std::pow(1 - c - z * std::sqrt(c), 3), std::pow(1 - c + z * std::sqrt(c), 3)};
}

// The gain a filter applies at step k, read from the plugin itself: the update is linear in the
// measurement (K depends on the prediction and R only), so feeding the same history to four
// instances and perturbing component j of the k-th measurement in instance j gives column j of K.
Eigen::Matrix<double, 9, 3> applied_gain(const std::string& type, const std::string& params,
                                         const std::vector<Measurement>& ms, int k) {
  const double delta[3] = {kSigmaRange, kSigmaAngle, kSigmaAngle};
  Eigen::Matrix<double, 9, 3> K;
  Eigen::VectorXd base;
  for (int j = -1; j < 3; ++j) {
    Run run(type, params);
    for (int i = 0; i < k; ++i) run.feed(ms[i]);
    Measurement m = ms[k];
    if (j >= 0) m.value(j) += delta[j];
    const Estimate& e = run.feed(m);
    REQUIRE(e.updated);
    if (j < 0)
      base = e.state;
    else
      K.col(j) = (Eigen::VectorXd(e.state) - base) / delta[j];
  }
  return K;
}

}  // namespace

// gain-transform gain vs filter.ekf's gain along paper 002's circle (same measurements)
TEST_CASE("gain vs filter.ekf gain on the paper 002 circle") {
  const int steps = 1700;
  const auto ms = circle_measurements(steps, 7);
  double worst_after_1s = 0.0;
  for (int k : {2, 3, 10, 40, 200, 800, 1600}) {
    const auto Kg = applied_gain("filter.gain_transform", kGt, ms, k);
    const auto Ke = applied_gain("filter.ekf", kEkf, ms, k);
    const double rel = (Kg - Ke).norm() / Ke.norm();
    double worst_col = 0.0;
    for (int j = 0; j < 3; ++j) worst_col = std::max(worst_col, (Kg.col(j) - Ke.col(j)).norm() / Ke.col(j).norm());
    INFO("t = " << k * kT << " s: |K_gt - K_ekf| / |K_ekf| = " << rel << ", worst column " << worst_col);
    // The gains differ by the cross-axis blocks the LOS filter drops: the line of sight turns by
    // 3.3 mrad per step, and the EKF's covariance, which remembers tens of steps, lags it by
    // ~0.1 rad, correlating range and cross-range errors (15 m vs 4.5 m). Measured: 2-4 % in
    // steady state, 7.7 % at 0.25 s while the two-point velocity variance collapses.
    CHECK(rel < 0.10);
    CHECK(worst_col < 0.13);
    if (k * kT >= 1.0) worst_after_1s = std::max(worst_after_1s, rel);
  }
  INFO("worst relative gain difference after 1 s: " << worst_after_1s);
  CHECK(worst_after_1s < 0.05);
}

// same tracking accuracy as filter.ekf on the circle: position RMSE within 2 %
TEST_CASE("circle accuracy within 2 percent of filter.ekf") {
  const int runs = 20, steps = 800;
  double sq_gt = 0, sq_ekf = 0;
  int n = 0;
  for (int r = 0; r < runs; ++r) {
    const auto ms = circle_measurements(steps, derive_seed(3, r, "circle"));
    Run gt("filter.gain_transform", kGt, r), ekf("filter.ekf", kEkf, r);
    for (int k = 0; k < steps; ++k) {
      const Estimate& eg = gt.feed(ms[k]);
      const Estimate& ee = ekf.feed(ms[k]);
      REQUIRE(eg.state.allFinite());
      if (k * kT >= 2.0) {
        sq_gt += (eg.enu.head<3>() - circle_position(k * kT)).squaredNorm();
        sq_ekf += (ee.enu.head<3>() - circle_position(k * kT)).squaredNorm();
        ++n;
      }
    }
  }
  const double rmse_gt = std::sqrt(sq_gt / n), rmse_ekf = std::sqrt(sq_ekf / n);
  INFO("position RMSE: gain transform " << rmse_gt << " m, EKF " << rmse_ekf << " m");
  CHECK(std::abs(rmse_gt / rmse_ekf - 1.0) < 0.02);
  CHECK(rmse_gt < 8.0);  // measurement cross-range error alone is 4.5 m, range 15 m
}

// consistent on a Singer target: ANEES (9 states) inside the 99 % chi-square band over 200 runs
TEST_CASE("Singer target: ANEES inside the 99 percent band") {
  // Truth drawn from the filter's own model (alpha 1/s, sigma_m 20 m/s2, exact discretisation),
  // 3 to 4 km from the radar, paper 002's radar (40 Hz, 15 m, 3 mrad). NEES at the last step
  // (10 s): independent across runs, so chi2(9M)/(9M) for an exact filter. The gain transform
  // drops the LOS cross-axis blocks; the test shows this costs no measurable consistency here.
  const int runs = 200, steps = 400;
  SingerModel model;
  model.alpha = 1.0;
  model.sigma = 20.0;
  const Eigen::Matrix3d F = model.axis_transition(kT), L = model.axis_noise(kT).llt().matrixL();
  double sum_gt = 0, sum_ekf = 0;
  for (int r = 0; r < runs; ++r) {
    Run gt("filter.gain_transform", kGt, r), ekf("filter.ekf", kEkf, r);
    Rng rng(derive_seed(41, r, "singer"));
    Eigen::Vector3d axes[3] = {{2500, -150, 0}, {2000, 100, 0}, {300, 10, 0}};
    for (auto& ax : axes) ax(2) = model.sigma * rng.normal();  // stationary acceleration
    for (int k = 0; k < steps; ++k) {
      const Vec3 p(axes[0](0), axes[1](0), axes[2](0));
      const Measurement m = radar(k * kT, p, Vec3::Zero(), &rng);
      const Estimate& eg = gt.feed(m);
      const Estimate& ee = ekf.feed(m);
      if (k == steps - 1) {
        Eigen::VectorXd truth(9);
        for (int a = 0; a < 3; ++a) truth.segment<3>(3 * a) = axes[a];
        REQUIRE(symmetric_psd(eg.covariance));
        sum_gt += nees(eg, truth);
        sum_ekf += nees(ee, truth);
      }
      for (auto& ax : axes) {
        ax = F * ax;
        ax += L * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
      }
    }
  }
  const double anees_gt = sum_gt / (9.0 * runs), anees_ekf = sum_ekf / (9.0 * runs);
  const auto [lo, hi] = chi2_band(9.0 * runs);
  INFO("ANEES gain transform " << anees_gt << ", EKF " << anees_ekf << ", 99 % band [" << lo << ", " << hi << "]");
  CHECK(anees_gt > lo);
  CHECK(anees_gt < hi);
  CHECK(std::abs(anees_gt - anees_ekf) < 0.05);
}

// paper 002's manoeuvre (150 -> 300 m/s, 60 deg climb): symmetric PSD covariance, recovery
TEST_CASE("paper 002 manoeuvre: PSD covariance and recovery") {
  Run run("filter.gain_transform", kGt);
  Rng rng(13);
  const Vec3 p0(-500, 1500, 100), v0(150, 0, 0);
  const double c60 = std::cos(std::numbers::pi / 3), s60 = std::sin(std::numbers::pi / 3);
  const Vec3 v1(300 * c60, 0, 300 * s60);
  double worst_nees_before = 0, final_nees = 0, max_el = 0;
  for (int k = 0; k <= 400; ++k) {
    const double t = k * kT;
    const Vec3 p = t < 3.0 ? Vec3(p0 + v0 * t) : Vec3(p0 + v0 * 3.0 + v1 * (t - 3.0));
    const Vec3 v = t < 3.0 ? v0 : v1;
    const Measurement m = radar(t, p, Vec3::Zero(), &rng);
    max_el = std::max(max_el, m.value(2));
    const Estimate& e = run.feed(m);
    REQUIRE(e.state.allFinite());
    if (!e.initialised) continue;
    REQUIRE(symmetric_psd(e.covariance));
    Eigen::VectorXd truth = Eigen::VectorXd::Zero(9);
    for (int a = 0; a < 3; ++a) {
      truth(3 * a) = p(a);
      truth(3 * a + 1) = v(a);
    }
    Vec6 err;
    err << e.enu.head<3>() - p, e.enu.tail<3>() - v;
    const double pv_nees = err.dot(e.enu_covariance.ldlt().solve(err));
    if (t > 1.0 && t < 3.0) worst_nees_before = std::max(worst_nees_before, pv_nees);
    if (k == 400) final_nees = pv_nees;
  }
  INFO("worst NEES (position, velocity) before the manoeuvre " << worst_nees_before << ", 7 s after it "
                                                               << final_nees << ", max elevation " << max_el);
  CHECK(max_el > 0.7);  // the climb takes the line of sight to ~45 deg, where cos(el) matters
  CHECK(worst_nees_before < 30.0);
  CHECK(final_nees < 30.0);  // chi2(6) exceeds 22.5 with probability 1e-3
}

// azimuth wrap: a target crossing the branch cut gives no 2 pi innovation (both conventions)
TEST_CASE("crossing the azimuth cut gives no 2 pi jump") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    Run run("filter.gain_transform", kGt);
    Rng rng(9);
    const bool nc = c == AzimuthConvention::NorthClockwise;
    const Vec3 v = nc ? Vec3(200, 0, 0) : Vec3(0, 200, 0);  // crosses due south / due west at t = 10 s
    const Vec3 p0 = nc ? Vec3(-2e3, -3e3, 300) : Vec3(-3e3, -2e3, 300);
    int crossings = 0;
    double prev_az = 0;
    for (int k = 0; k < 800; ++k) {
      const double t = k * kT;
      const Measurement m = radar(t, p0 + v * t, Vec3::Zero(), &rng, c);
      if (k > 0 && std::abs(m.value(1) - prev_az) > std::numbers::pi) ++crossings;
      prev_az = m.value(1);
      const Estimate& e = run.feed(m);
      if (e.updated) {
        CHECK(std::abs(e.innovation(1)) < 6 * std::sqrt(e.innovation_covariance(1, 1)));
        CHECK(e.nis < 40.0);
      }
    }
    CHECK(crossings >= 1);
    const Estimate& e = run.out.estimates.back();
    CHECK((e.enu.head<3>() - (p0 + v * 799 * kT)).norm() < 20.0);
  }
}

// a pass straight over the radar stays finite with a symmetric PSD covariance
TEST_CASE("a pass straight overhead stays finite and PSD") {
  for (double offset : {0.0, 0.3, 30.0}) {
    INFO("horizontal miss distance " << offset << " m");
    Run run("filter.gain_transform", kGt);
    Rng rng(31);
    const Vec3 v(150, 0, 0), p0(-1500, offset, 1500);  // overhead at t = 10 s
    double worst_err = 0;
    for (int k = 0; k < 800; ++k) {
      const double t = k * kT;
      const Vec3 p = p0 + v * t;
      const Estimate& e = run.feed(radar(t, p, Vec3::Zero(), &rng));
      REQUIRE(e.state.allFinite());
      if (e.initialised) REQUIRE(symmetric_psd(e.covariance));
      if (t > 9 && t < 11) worst_err = std::max(worst_err, (e.enu.head<3>() - p).norm());
    }
    INFO("worst position error over the pass " << worst_err << " m, warnings " << run.diag.warnings.size());
    CHECK(worst_err < 25.0);
    CHECK(run.diag.warnings.size() == (offset < 1.0 ? 1u : 0u));
    const Estimate& e = run.out.estimates.back();
    CHECK((e.enu.head<3>() - (p0 + v * 799 * kT)).norm() < 20.0);
  }
}

// an invalid measurement makes the filter coast: prediction only, covariance grows
TEST_CASE("an invalid measurement makes the filter coast") {
  Run run("filter.gain_transform", kGt);
  for (int k = 0; k < 40; ++k) run.feed(radar(k * kT, circle_position(k * kT), Vec3::Zero(), nullptr));
  Measurement bad = radar(40 * kT, Vec3(1e9, 1e9, 1e9), Vec3::Zero(), nullptr);
  bad.valid = false;
  const Estimate& coast = run.feed(bad);
  REQUIRE(run.out.estimates.size() == 41);
  CHECK(coast.initialised);
  CHECK_FALSE(coast.updated);
  CHECK(coast.innovation.size() == 0);
  CHECK(coast.time == Approx(1.0));
  CHECK((coast.enu.head<3>() - circle_position(1.0)).norm() < 5.0);
  CHECK(coast.covariance.trace() > run.out.estimates[39].covariance.trace());
  Measurement nan = radar(41 * kT, circle_position(41 * kT), Vec3::Zero(), nullptr);
  nan.value(2) = std::numeric_limits<double>::quiet_NaN();
  const Estimate& coast2 = run.feed(nan);
  CHECK_FALSE(coast2.updated);
  CHECK(coast2.state.allFinite());
  CHECK(run.diag.warnings.size() == 1);
  Measurement empty;  // an invalid measurement need not carry a value
  empty.time = 42 * kT;
  empty.valid = false;
  CHECK_FALSE(run.feed(empty).updated);
  const Estimate& back = run.feed(radar(43 * kT, circle_position(43 * kT), Vec3::Zero(), nullptr));
  CHECK(back.updated);
  CHECK(symmetric_psd(back.covariance));
}

// the first two measurements initialise, older ones are skipped, a range rate is ignored
TEST_CASE("two-point init and old measurements skipped") {
  Run run("filter.gain_transform", kGt), with_rr("filter.gain_transform", kGt);
  Rng rng(2);
  std::vector<Measurement> ms;
  for (int k = 0; k < 30; ++k) {
    const Vec3 p = circle_position(k * kT), v(-200 * std::sin(k * kT * 200 / 1500), 200 * std::cos(k * kT * 200 / 1500), 0);
    Measurement m = radar(k * kT, p, Vec3::Zero(), &rng, AzimuthConvention::NorthClockwise, true, v);
    with_rr.feed(m);
    m.has_range_rate = false;
    m.value.conservativeResize(3);
    m.covariance.conservativeResize(3, 3);
    ms.push_back(m);
    run.feed(m);
  }
  const auto& est = run.out.estimates;
  CHECK_FALSE(est[0].initialised);
  CHECK(est[0].state.isZero());
  REQUIRE(est[1].initialised);
  CHECK_FALSE(est[1].updated);
  const Vec3 z0 = spherical_to_enu(ms[0].value(0), ms[0].value(1), ms[0].value(2), ms[0].azimuth);
  const Vec3 z1 = spherical_to_enu(ms[1].value(0), ms[1].value(1), ms[1].value(2), ms[1].azimuth);
  for (int a = 0; a < 3; ++a) {
    CHECK(est[1].state(3 * a) == Approx(z1(a)));
    CHECK(est[1].state(3 * a + 1) == Approx((z1(a) - z0(a)) / kT));
    CHECK(est[1].state(3 * a + 2) == 0.0);
  }
  // Initial position covariance = the converted covariance of the second point.
  const Mat3 J = spherical_to_enu_jacobian(ms[1].value(0), ms[1].value(1), ms[1].value(2), ms[1].azimuth);
  const Mat3 Rc = J * ms[1].covariance.topLeftCorner<3, 3>() * J.transpose();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) CHECK(est[1].enu_covariance(a, b) == Approx(Rc(a, b)).margin(1e-9 * Rc.norm()));
  for (size_t k = 0; k < est.size(); ++k) CHECK(est[k].state == with_rr.out.estimates[k].state);
  CHECK(with_rr.out.estimates.back().innovation.size() == 3);
  run.filter->on_measurement(ms[10], 0);
  CHECK(est.size() == 30);
  REQUIRE(run.diag.skips.size() == 1);
  CHECK(run.diag.skips[0].node == "f");
}

// noise handles: spherical R and per-axis sigma_m that the prediction follows
TEST_CASE("noise handles: spherical R and sigma_m") {
  Run a("filter.gain_transform", kGt), b("filter.gain_transform", kGt);
  auto* fb = dynamic_cast<Filter*>(b.filter.get());
  REQUIRE(fb);
  const NoiseHandles h = fb->noise();
  CHECK(h.measurement.space == MeasurementSpace::Spherical);
  REQUIRE(h.process.count == 3);
  CHECK(h.process.values[2] == 20.0);
  REQUIRE(h.measurement.R);
  for (int k = 0; k < 20; ++k) {
    if (k == 10) h.process.values[2] = 200.0;  // an adapter raising sigma_m up
    const Measurement m = radar(k * kT, circle_position(k * kT), Vec3::Zero(), nullptr);
    a.feed(m);
    b.feed(m);
  }
  CHECK(h.measurement.R->rows() == 3);
  CHECK((*h.measurement.R)(0, 0) == Approx(kSigmaRange * kSigmaRange));
  const auto& ea = a.out.estimates.back();
  const auto& eb = b.out.estimates.back();
  CHECK(eb.covariance(8, 8) > 10 * ea.covariance(8, 8));   // up acceleration
  // East is not retuned, but per-axis sigma_m are smeared over the LOS axes (only the diagonal of
  // D' diag(sigma^2) D is kept): the range axis, pointing east here, gets sigma_up^2 sin^2(el) =
  // 0.0099 x 200^2 = 396 added to its 400 (m/s2)^2, so at most twice the east variance.
  CHECK(eb.covariance(2, 2) < 2.1 * ea.covariance(2, 2));
  CHECK(symmetric_psd(eb.covariance));
}

TEST_CASE("wrong inputs and parameters are clear errors") {
  Run run("filter.gain_transform", kGt);
  Measurement m = radar(0, Vec3(1e3, 2e3, 3e2), Vec3::Zero(), nullptr);
  m.frame = Frame::Cartesian;
  CHECK_THROWS_WITH(run.filter->on_measurement(m, 0), Catch::Contains("spherical") && Catch::Contains("node 'f'"));
  m.frame = Frame::Spherical;
  m.has_range_rate = true;  // flag without the 4th value
  CHECK_THROWS_AS(run.filter->on_measurement(m, 0), DataError);

  auto error = [](const std::string& params) {
    try {
      test::make("filter.gain_transform", params);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(error("{}"), Catch::Contains("singer_sigma"));
  CHECK_THAT(error("{ singer_sigma: 3 mrad }"), Catch::Contains("singer_sigma"));
  CHECK_THAT(error("{ singer_sigma: -1 m/s2 }"), Catch::Contains("singer_sigma"));
  CHECK_THAT(error("{ singer_sigma: 20 m/s2, singer_alpha: 0 1/s }"), Catch::Contains("singer_alpha"));
  CHECK_THAT(error("{ singer_sigma: 20 m/s2, frame_change: rotate }"), Catch::Contains("frame_change"));
  // The transition-model block offers paper 002's Singer model only: another motion is refused.
  CHECK_THAT(error("{ singer_sigma: 20 m/s2, motion: constant_velocity }"), Catch::Contains("motion"));
  CHECK_THAT(error("{ singer_sigma: 20 m/s2, q: 1 m2/s3 }"), Catch::Contains("unknown parameter 'q'"));
  CHECK(error("{ singer_sigma: 20 m/s2, motion: singer }") == "no error");
  CHECK(error("{ singer_sigma: 20 m/s2, frame_change: carry, initial_sigma_acceleration: 5 m/s2 }") == "no error");
}
