// Purpose: tests of convert.unbiased: unbiased given the truth and averaged true covariance, by Gauss–Hermite cubature; Mo et al.'s eq 11.
#include "conversion/converter_common_checks.hpp"

#include <cmath>

using namespace trackflow;
using namespace trackflow::test;

namespace {
const char* kType = "convert.unbiased";
const Vec3 kSensor(100.0, -50.0, 3.0);
const Vec3 kSigmas(30.0, 0.15, 0.10);

// Mo et al.'s estimator written from its definition (eq 9, 12): divide by E[cos] of each angle error.
Vec3 mo_estimate(const Vec3& m, AzimuthConvention c) {
  const double la = std::exp(-0.5 * kSigmas(1) * kSigmas(1)), le = std::exp(-0.5 * kSigmas(2) * kSigmas(2));
  const Vec3 p = enu_of(m, c);
  return {p(0) / (la * le), p(1) / (la * le), p(2) / le};
}
}  // namespace

// the converted mean is unbiased given the true position (cubature over the measurement error)
TEST_CASE("mean is unbiased given the true position") {
  auto conv = make(kType);
  OneShot out;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (double az : {2.3, -0.7}) {
      const Vec3 truth(20e3, az, 0.4);
      const Mat3 S = kSigmas.cwiseProduct(kSigmas).asDiagonal();
      // E[z | t] with m ~ N(t, S), z produced by the plugin itself at every cubature node.
      Vec3 expected_z = Vec3::Zero();
      for_each_gauss_hermite<3>(truth, S, 12, [&](const Vec3& m, double w) {
        expected_z += w * out.convert(*conv, spherical_measurement(m(0), m(1), m(2), kSigmas, c, kSensor)).value.head<3>();
      });
      CHECK((expected_z - kSensor - enu_of(truth, c)).norm() < 1e-8 * truth(0));
      // ... while the classical p(m) is short by (1 - λ²)·r ≈ 400 m here: the check can fail.
      const auto classical = gauss_hermite_moments<3, 3>(truth, S, 12, [c](const Vec3& m) { return enu_of(m, c); });
      CHECK((classical.mean - enu_of(truth, c)).norm() > 100.0);
    }
  }
}

// covariance is the truth-conditioned covariance averaged over the truth given the measurement (cubature)
TEST_CASE("covariance is the averaged truth-conditioned one") {
  auto conv = make(kType);
  OneShot out;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const Vec3 s(20e3, 2.3, 0.4);
    const Measurement m = spherical_measurement(s(0), s(1), s(2), kSigmas, c, kSensor);
    const Measurement got = out.convert(*conv, m);
    const Mat3 S = kSigmas.cwiseProduct(kSigmas).asDiagonal();
    const auto ref = averaged_truth_conditioned_moments<3, 3>(s, S, 8, [c](const Vec3& mm) { return mo_estimate(mm, c); });
    CHECK((got.value.head<3>() - kSensor - mo_estimate(s, c)).norm() < 1e-9 * s(0));
    CHECK(relative_difference(Mat3(got.covariance), ref.covariance) < 1e-8);
  }
}

// range-rate cross-covariance is the averaged truth-conditioned covariance (cubature)
TEST_CASE("range-rate cross-covariance matches cubature") {
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
    const auto ref = averaged_truth_conditioned_moments<4, 4>(m4, spherical_covariance4(m), 8, [c](const Vec4& mm) {
      Vec4 y;
      y << mo_estimate(mm.head<3>(), c), mm(3);
      return y;
    });
    CHECK(relative_difference(Vec3(got.covariance.block<3, 1>(0, 3)), Vec3(ref.covariance.block<3, 1>(0, 3))) < 1e-8);
    CHECK(got.covariance(3, 3) == rr_sigma * rr_sigma);
  }
}

// Mo et al. (1998) eq 11a-f for azimuth β from x toward y, elevation η, λ' = λ⁴; transcribed
// independently of conversion_moments.hpp.
TEST_CASE("matches Mo et al.'s eq 11 (x_counterclockwise)") {
  auto conv = make(kType);
  OneShot out;
  const double r = 15e3, b = 0.9, e = 0.35, sr2 = 400.0, sb2 = 0.02, se2 = 0.01;
  const Measurement m = spherical_measurement(r, b, e, Vec3(std::sqrt(sr2), std::sqrt(sb2), std::sqrt(se2)),
                                              AzimuthConvention::XCounterClockwise);
  const Measurement got = out.convert(*conv, m);
  const double lb = std::exp(-sb2 / 2), le = std::exp(-se2 / 2), lbp = std::pow(lb, 4), lep = std::pow(le, 4);
  const double ib2 = 1 / (lb * lb), ie2 = 1 / (le * le);
  const double cb = std::cos(b), sb = std::sin(b);
  const double c2b = std::cos(2 * b), s2b = std::sin(2 * b), c2e = std::cos(2 * e), s2e = std::sin(2 * e);
  const double A = r * r + 2 * sr2, B = r * r + sr2;
  Vec3 mean(r * cb * std::cos(e) / (lb * le), r * sb * std::cos(e) / (lb * le), r * std::sin(e) / le);  // eq 9
  Mat3 R;
  R(0, 0) = 0.25 * ib2 * ie2 * A * (1 + lbp * lbp * c2b) * (1 + lep * lep * c2e) - 0.25 * B * (1 + lbp * c2b) * (1 + lep * c2e);
  R(1, 1) = 0.25 * ib2 * ie2 * A * (1 - lbp * lbp * c2b) * (1 + lep * lep * c2e) - 0.25 * B * (1 - lbp * c2b) * (1 + lep * c2e);
  R(2, 2) = 0.5 * ie2 * A * (1 - lep * lep * c2e) - 0.5 * B * (1 - lep * c2e);
  R(0, 1) = R(1, 0) = 0.25 * ib2 * ie2 * lbp * lbp * A * s2b * (1 + lep * lep * c2e) - 0.25 * lbp * B * s2b * (1 + lep * c2e);
  R(0, 2) = R(2, 0) = 0.5 * lb * ie2 * lep * lep * A * cb * s2e - 0.5 * lb * lep * B * cb * s2e;
  R(1, 2) = R(2, 1) = 0.5 * lb * ie2 * lep * lep * A * sb * s2e - 0.5 * lb * lep * B * sb * s2e;
  CHECK((got.value.head<3>() - mean).norm() < 1e-9 * r);
  CHECK(relative_difference(Mat3(got.covariance), R) < 1e-9);
}

// shared behaviour: pass-through, bad data, small-error limit, azimuth conventions
TEST_CASE("shared converter behaviour") {
  check_pass_through(kType);
  check_bad_data(kType);
  check_small_error_limit(kType);
  check_convention_equivalence(kType);
}
