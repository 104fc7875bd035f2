// Purpose: tests of convert.unbiased_modified against posterior moments by Gauss–Hermite cubature and Duan et al.'s printed expressions.
#include "conversion/converter_common_checks.hpp"

#include <cmath>

using namespace trackflow;
using namespace trackflow::test;

namespace {
const char* kType = "convert.unbiased_modified";
const Vec3 kSensor(100.0, -50.0, 3.0);
// Large errors (8.6° azimuth) so that every λ term matters well above the tolerances.
const Vec3 kSigmas(30.0, 0.15, 0.10);
}  // namespace

// mean and covariance are the posterior moments of the true position (cubature), both conventions
TEST_CASE("mean and covariance are posterior moments") {
  auto conv = make(kType);
  OneShot out;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (double az : {2.3, -0.7}) {
      const Vec3 s(20e3, az, 0.4);
      const Measurement m = spherical_measurement(s(0), s(1), s(2), kSigmas, c, kSensor);
      const Measurement got = out.convert(*conv, m);
      const Mat3 S = kSigmas.cwiseProduct(kSigmas).asDiagonal();
      // t ~ N(m, S): the truth given the measurement under a flat prior in (r, az, el).
      const auto ref = gauss_hermite_moments<3, 3>(s, S, 16, [c](const Vec3& t) { return enu_of(t, c); });
      CHECK((got.value.head<3>() - kSensor - ref.mean).norm() < 1e-9 * s(0));
      CHECK(relative_difference(Mat3(got.covariance), ref.covariance) < 1e-9);
    }
  }
}

// range-rate cross-covariance is the posterior covariance of (position, range rate) (cubature)
TEST_CASE("range-rate cross-covariance is posterior") {
  auto conv = make(kType);
  OneShot out;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const Vec3 s(20e3, 1.1, 0.25);
    const double rr_sigma = 2.0;
    const Vec3 cross(0.5 * kSigmas(0) * rr_sigma, -0.3 * kSigmas(1) * rr_sigma, 0.2 * kSigmas(2) * rr_sigma);
    const Measurement m = spherical_measurement(s(0), s(1), s(2), kSigmas, c, kSensor, 35.0, rr_sigma * rr_sigma, cross);
    const Measurement got = out.convert(*conv, m);
    Vec4 m4;
    m4 << s, 35.0;
    const auto ref = gauss_hermite_moments<4, 4>(m4, spherical_covariance4(m), 12, [c](const Vec4& t) {
      Vec4 y;
      y << enu_of(t.head<3>(), c), t(3);
      return y;
    });
    CHECK(got.value(3) == 35.0);
    CHECK(relative_difference(Mat4(got.covariance), ref.covariance) < 1e-9);
  }
}

// Duan, Han & Li (2004) give the modified conversion element by element for azimuth measured
// from x toward y (β) and elevation η; transcribed independently of conversion_moments.hpp.
// matches Duan, Han & Li's element-wise expressions (x_counterclockwise)
TEST_CASE("matches Duan Han and Li element-wise") {
  auto conv = make(kType);
  OneShot out;
  const double r = 15e3, b = 0.9, e = 0.35, sr2 = 400.0, sb2 = 0.02, se2 = 0.01;
  const Measurement m = spherical_measurement(r, b, e, Vec3(std::sqrt(sr2), std::sqrt(sb2), std::sqrt(se2)),
                                              AzimuthConvention::XCounterClockwise);
  const Measurement got = out.convert(*conv, m);
  const double lb = std::exp(-sb2 / 2), le = std::exp(-se2 / 2), lb4 = std::pow(lb, 4), le4 = std::pow(le, 4);
  const double cb = std::cos(b), sb = std::sin(b), ce = std::cos(e), se = std::sin(e), R2 = r * r + sr2;
  const double c2b = std::cos(2 * b), s2b = std::sin(2 * b), c2e = std::cos(2 * e), s2e = std::sin(2 * e);
  Vec3 mean(lb * le * r * cb * ce, lb * le * r * sb * ce, le * r * se);
  Mat3 R;
  R(0, 0) = -lb * lb * le * le * r * r * cb * cb * ce * ce + 0.25 * R2 * (1 + lb4 * c2b) * (1 + le4 * c2e);
  R(1, 1) = -lb * lb * le * le * r * r * sb * sb * ce * ce + 0.25 * R2 * (1 - lb4 * c2b) * (1 + le4 * c2e);
  R(2, 2) = -le * le * r * r * se * se + 0.5 * R2 * (1 - le4 * c2e);
  R(0, 1) = R(1, 0) = -lb * lb * le * le * r * r * sb * cb * ce * ce + 0.25 * R2 * lb4 * s2b * (1 + le4 * c2e);
  R(0, 2) = R(2, 0) = -lb * le * le * r * r * cb * se * ce + 0.5 * R2 * lb * le4 * cb * s2e;
  R(1, 2) = R(2, 1) = -lb * le * le * r * r * sb * se * ce + 0.5 * R2 * lb * le4 * sb * s2e;
  CHECK((got.value.head<3>() - mean).norm() < 1e-9 * r);
  CHECK(relative_difference(Mat3(got.covariance), R) < 1e-9);
}

// the covariance stays positive definite and free of cancellation at tiny angle errors
TEST_CASE("covariance stays PD at tiny angle errors") {
  auto conv = make(kType);
  OneShot out;
  // 1 µrad at 1000 km: the angle part of the variance is 1 m², r² is 1e12 m².
  const Measurement m = spherical_measurement(1e6, 0.7, 0.2, Vec3(0.5, 1e-6, 1e-6), AzimuthConvention::NorthClockwise);
  const Measurement got = out.convert(*conv, m);
  const Mat3 J = numerical_jacobian(Vec3(1e6, 0.7, 0.2), AzimuthConvention::NorthClockwise);
  const Mat3 ref = J * Vec3(0.25, 1e-12, 1e-12).asDiagonal() * J.transpose();
  CHECK(relative_difference(Mat3(got.covariance), ref) < 1e-6);
  CHECK(Eigen::LLT<Mat3>(Mat3(got.covariance)).info() == Eigen::Success);
}

// shared behaviour: pass-through, bad data, small-error limit, azimuth conventions
TEST_CASE("shared converter behaviour") {
  check_pass_through(kType);
  check_bad_data(kType);
  check_small_error_limit(kType);
  check_convention_equivalence(kType);
}

// correlated (r, az, el) errors are converted with their variances and reported, not ignored silently
TEST_CASE("correlated spherical errors are reported") {
  auto conv = trackflow::test::make("convert.unbiased_modified");
  trackflow::test::Collector out;
  out.attach_to(*conv);
  auto measure = [&](double correlation) {
    trackflow::Diagnostics d;
    conv->start_run({0, 1, &d});
    trackflow::Measurement m;
    m.frame = trackflow::Frame::Spherical;
    m.value = trackflow::Vec3(20e3, 0.5, 0.1);
    m.covariance = trackflow::MeasCov::Zero(3, 3);
    m.covariance.diagonal() << 100.0, 1e-6, 1e-6;
    m.covariance(0, 1) = m.covariance(1, 0) = correlation * std::sqrt(100.0 * 1e-6);
    conv->on_measurement(m, 0);
    conv->end_run();
    return d.warnings;
  };
  CHECK(measure(0.0).empty());
  const auto w = measure(0.3);
  REQUIRE(w.size() == 1);
  CHECK(w[0].message.find("1 measurement(s) had correlated") != std::string::npos);
  CHECK(w[0].message.find("0.3") != std::string::npos);
}
