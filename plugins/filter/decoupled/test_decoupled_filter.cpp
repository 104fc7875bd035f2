// Purpose: tests of the filter.decoupled plugin: agreement with filter.kalman where the decoupling is exact, accuracy and consistency where it is not, covariance health, coasting, errors.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

Measurement cartesian(double t, const Vec3& z, const Mat3& R, const Vec3& sensor) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Cartesian;
  m.sensor_position = sensor;
  m.value = z;
  m.covariance = R;
  return m;
}

// Classical conversion of a noisy spherical look (x-counterclockwise azimuth), done here with the
// geometry header so the test does not depend on a converter plugin.
Measurement classical_look(double t, const Vec3& target, const Vec3& sensor, const Vec3& sigmas, Rng& rng) {
  const Vec3 rae = enu_to_spherical(target - sensor, AzimuthConvention::XCounterClockwise);
  const double r = rae(0) + sigmas(0) * rng.normal();
  const double az = rae(1) + sigmas(1) * rng.normal();
  const double el = rae(2) + sigmas(2) * rng.normal();
  const Mat3 J = spherical_to_enu_jacobian(r, az, el, AzimuthConvention::XCounterClockwise);
  const Mat3 R = J * sigmas.cwiseProduct(sigmas).asDiagonal() * J.transpose();
  return cartesian(t, spherical_to_enu(r, az, el, AzimuthConvention::XCounterClockwise) + sensor,
                   0.5 * (R + R.transpose()), sensor);
}

struct Ensemble {
  double sq_position = 0, nees = 0;
  long count = 0;
  double rmse() const { return std::sqrt(sq_position / count); }
  double anees() const { return nees / (6.0 * count); }
  void add(const Estimate& e, const Vec3& p, const Vec3& v) {
    Vec6 err;
    err << e.enu.head<3>() - p, e.enu.tail<3>() - v;
    sq_position += err.head<3>().squaredNorm();
    nees += err.dot(e.enu_covariance.ldlt().solve(err));
    ++count;
  }
};

bool symmetric_psd(const Mat6& P) {
  if (!P.allFinite() || (P - P.transpose()).norm() != 0.0) return false;
  const Eigen::SelfAdjointEigenSolver<Mat6> es(P);
  return es.eigenvalues().minCoeff() > -1e-12 * es.eigenvalues().maxCoeff();
}

}  // namespace

// decoupled filter reproduces filter.kalman when R is diagonal in a line of sight that does not turn
TEST_CASE("reproduces filter.kalman for a fixed LOS") {
  auto dkf = test::make("filter.decoupled", "{ q: 0.5 m2/s3 }");
  auto kf = test::make("filter.kalman", "{ q: 0.5 m2/s3 }");
  test::Collector dout, kout;
  dout.attach_to(*dkf);
  kout.attach_to(*kf);
  Diagnostics d;
  dkf->start_run({0, 1, &d});
  kf->start_run({0, 1, &d});
  Rng rng(4);
  const Vec3 sensor(100, -50, 10);
  const Vec3 u = Vec3(0.6, -0.7, 0.3).normalized();
  Mat3 D;
  D.col(0) = u;
  D.col(1) = Vec3(-u.y(), u.x(), 0).normalized();
  D.col(2) = D.col(0).cross(D.col(1));
  // Range-only noise on a radial track keeps the measured line of sight fixed; R still has
  // cross-range variances (the filter is not told the noise is radial).
  const double sr = 3.0;
  const Mat3 R = D * Vec3(sr * sr, 25.0, 64.0).asDiagonal() * D.transpose();
  for (int k = 0; k < 300; ++k) {
    const double t = 0.1 * k;
    Measurement m = cartesian(t, sensor + (8000.0 - 60.0 * t + sr * rng.normal()) * u, R, sensor);
    if (k == 150) m.valid = false;
    dkf->on_measurement(m, 0);
    kf->on_measurement(m, 0);
  }
  REQUIRE(dout.estimates.size() == kout.estimates.size());
  for (size_t k = 1; k < dout.estimates.size(); ++k) {
    const Estimate& a = dout.estimates[k];
    const Estimate& b = kout.estimates[k];
    REQUIRE(a.initialised);
    CHECK(a.updated == b.updated);
    CHECK((a.state - b.state).norm() < 1e-9 * b.state.norm());
    CHECK((a.covariance - b.covariance).norm() < 1e-9 * b.covariance.norm());
    CHECK((a.enu_covariance - b.enu_covariance).norm() < 1e-9 * b.enu_covariance.norm());
    if (b.updated) CHECK(a.nis == Approx(b.nis).epsilon(1e-8));
  }
}

// A target crossing 500 m from the sensor at 200 m/s: the line of sight turns by 90 degrees in
// a few seconds and the cross-range noise (5 m) is larger than the range noise (2 m), so the
// decoupling is an approximation. The truth has the white acceleration the filters assume, so the
// full Kalman filter on the same converted measurements is the optimal reference.
// on a crossing target the decoupled filter stays close to the full Kalman filter in accuracy and consistency
TEST_CASE("crossing target: close to the full Kalman filter") {
  const double q = 0.5, T = 0.1;
  auto reproject = test::make("filter.decoupled", "{ q: 0.5 m2/s3 }");
  auto carry = test::make("filter.decoupled", "{ q: 0.5 m2/s3, frame_change: carry }");
  auto kf = test::make("filter.kalman", "{ q: 0.5 m2/s3 }");
  test::Collector rout, cout, kout;
  rout.attach_to(*reproject);
  cout.attach_to(*carry);
  kout.attach_to(*kf);
  Ensemble er, ec, ek;
  const int runs = 150;
  const Vec3 sigmas(2.0, 10e-3, 10e-3);
  const Eigen::Matrix2d Qa =
      (Eigen::Matrix2d() << q * T * T * T / 3, q * T * T / 2, q * T * T / 2, q * T).finished();
  const Eigen::Matrix2d L = Qa.llt().matrixL();
  for (int run = 0; run < runs; ++run) {
    Diagnostics d;
    for (auto* c : {reproject.get(), carry.get(), kf.get()}) c->start_run({static_cast<std::uint64_t>(run), 1, &d});
    rout.estimates.clear();
    cout.estimates.clear();
    kout.estimates.clear();
    Rng rng(derive_seed(9, run, "crossing"));
    Vec3 p(-4000, 500, 100), v(200, 0, 0);
    for (int k = 0; k < 400; ++k) {
      const Measurement m = classical_look(k * T, p, Vec3::Zero(), sigmas, rng);
      reproject->on_measurement(m, 0);
      carry->on_measurement(m, 0);
      kf->on_measurement(m, 0);
      if (k >= 50) {  // after the initial transient
        er.add(rout.estimates.back(), p, v);
        ec.add(cout.estimates.back(), p, v);
        ek.add(kout.estimates.back(), p, v);
      }
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector2d w = L * Eigen::Vector2d(rng.normal(), rng.normal());
        p(a) += v(a) * T + w(0);
        v(a) += w(1);
      }
    }
  }
  INFO("RMSE kalman " << ek.rmse() << " reproject " << er.rmse() << " carry " << ec.rmse());
  INFO("ANEES kalman " << ek.anees() << " reproject " << er.anees() << " carry " << ec.anees());
  // The reference is consistent: ANEES within the 99 % band of chi2(6 * 150 * 350) / (6 * 150 * 350)
  // would be +-0.5 %, but successive steps are strongly correlated, so allow +-5 %.
  CHECK(ek.anees() == Approx(1.0).epsilon(0.05));
  // Paired comparison on the same measurements: the decoupled filters lose (almost) nothing. (The
  // reference is only nearly optimal: the converted R depends on the noisy measurement.)
  for (const Ensemble* e : {&er, &ec}) {
    CHECK(e->rmse() < 1.05 * ek.rmse());
    CHECK(e->rmse() > 0.98 * ek.rmse());
    CHECK(e->anees() == Approx(ek.anees()).epsilon(0.10));
  }
}

// published covariance stays symmetric positive semi-definite over a long run with a turning line of sight
TEST_CASE("covariance stays symmetric PSD on a long run") {
  for (const char* params : {"{ q: 0.01 m2/s3 }", "{ q: 100 m2/s3, frame_change: carry }", "{ sigma_accel: 3 m/s2 }"}) {
    INFO(params);
    auto dkf = test::make("filter.decoupled", params);
    test::Collector out;
    out.attach_to(*dkf);
    Diagnostics d;
    dkf->start_run({0, 1, &d});
    Rng rng(17);
    const int steps = 30000;
    int bad = 0, updated = 0;
    for (int k = 0; k < steps; ++k) {
      const double t = 0.05 * k;
      // Circles the sensor at 2 km every 100 s, 150 m up; R's scale jumps over eight decades.
      const double a = 2.0 * 3.141592653589793 * t / 100.0;
      const Vec3 p(2000 * std::cos(a), 2000 * std::sin(a), 150);
      const double scale = std::pow(10.0, 4.0 * std::sin(0.0137 * k));
      Measurement m = classical_look(t, p, Vec3::Zero(), Vec3(0.5, 3e-3, 1e-4) * std::sqrt(scale), rng);
      m.valid = k % 97 != 0;
      dkf->on_measurement(m, 0);
      const Estimate& e = out.estimates.back();
      if (!e.initialised) continue;
      updated += e.updated;
      bad += !symmetric_psd(e.enu_covariance) || !e.enu.allFinite();
    }
    CHECK(bad == 0);
    CHECK(updated > steps * 0.95);
    CHECK(d.warnings.empty());
  }
}

TEST_CASE("an invalid measurement makes the filter coast") {
  auto dkf = test::make("filter.decoupled", "{ q: 1 m2/s3 }");
  test::Collector out;
  out.attach_to(*dkf);
  Diagnostics d;
  dkf->start_run({0, 1, &d});
  const Mat3 R = Mat3::Identity() * 9.0;
  for (int k = 0; k < 5; ++k) dkf->on_measurement(cartesian(k, Vec3(1000 + 100.0 * k, 500, 50), R, Vec3::Zero()), 0);
  Measurement bad = cartesian(5, Vec3(1e9, 1e9, 1e9), R, Vec3::Zero());
  bad.valid = false;
  dkf->on_measurement(bad, 0);
  REQUIRE(out.estimates.size() == 6);
  CHECK_FALSE(out.estimates[0].initialised);
  const auto& coast = out.estimates.back();
  CHECK_FALSE(coast.updated);
  CHECK(coast.initialised);
  CHECK(coast.enu(0) == Approx(1500).epsilon(1e-3));
  CHECK(coast.enu(3) == Approx(100).epsilon(1e-3));
  CHECK(coast.enu_covariance(0, 0) > out.estimates[4].enu_covariance(0, 0));
}

// filter.decoupled: wrong inputs and parameters are clear errors, and R is exposed in Cartesian position
// space
TEST_CASE("wrong inputs are errors and R is Cartesian") {
  auto dkf = test::make("filter.decoupled");
  Diagnostics d;
  dkf->start_run({0, 1, &d});
  Measurement m = cartesian(0, Vec3(1, 2, 3), Mat3::Identity(), Vec3::Zero());
  m.frame = Frame::Spherical;
  CHECK_THROWS_AS(dkf->on_measurement(m, 0), DataError);
  CHECK_THROWS_WITH(dkf->on_measurement(m, 0), Catch::Contains("convert."));
  CHECK_THROWS_WITH(test::make("filter.decoupled", "{ q: 1 m2/s3, sigma_accel: 1 m/s2 }"), Catch::Contains("not both"));
  CHECK_THROWS_WITH(test::make("filter.decoupled", "{ frame_change: rotate }"), Catch::Contains("frame_change"));
  auto* f = dynamic_cast<Filter*>(dkf.get());
  REQUIRE(f);
  const NoiseHandles h = f->noise();
  REQUIRE(h.measurement.R);
  CHECK(h.measurement.space == MeasurementSpace::CartesianPosition);
  CHECK(h.process.count == 1);
}

// a measurement noise that is not a covariance is refused with a warning, never a NaN
TEST_CASE("non-covariance measurement noise is refused") {
  auto dkf = test::make("filter.decoupled");
  test::Collector out;
  out.attach_to(*dkf);
  Diagnostics d;
  dkf->start_run({0, 1, &d});
  const Mat3 R = Mat3::Identity() * 4.0;
  for (int k = 0; k < 3; ++k) dkf->on_measurement(cartesian(k, Vec3(1000 + 10.0 * k, 0, 100), R, Vec3::Zero()), 0);
  Mat3 negative = R;
  negative(1, 1) = -4.0;
  dkf->on_measurement(cartesian(3, Vec3(1030, 0, 100), negative, Vec3::Zero()), 0);
  const auto& e = out.estimates.back();
  CHECK_FALSE(e.updated);
  CHECK(e.enu.allFinite());
  CHECK(e.enu_covariance.allFinite());
  REQUIRE(d.warnings.size() == 1);
  CHECK_THAT(d.warnings[0].message, Catch::Contains("not a covariance"));
}
