// Purpose: tests of convert.debiased: average true bias and covariance by nested Gauss–Hermite cubature; Lerro & Bar-Shalom's 2-D form.
#include "conversion/converter_common_checks.hpp"

#include <cmath>

using namespace trackflow;
using namespace trackflow::test;

namespace {
const char* kType = "convert.debiased";
const Vec3 kSensor(100.0, -50.0, 3.0);
const Vec3 kSigmas(30.0, 0.15, 0.10);
}  // namespace

// Lerro & Bar-Shalom's definitions: bias given the truth b(t) = E[p(m') | t] - p(t), averaged
// over the truth given the measurement and subtracted; covariance E_t|m[ Cov[p(m') | t] ].
// mean and covariance are the average true bias and covariance (nested cubature), both conventions
TEST_CASE("mean and covariance match nested cubature") {
  auto conv = make(kType);
  OneShot out;
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (double az : {2.3, -0.7}) {
      const Vec3 s(20e3, az, 0.4);
      const Measurement got = out.convert(*conv, spherical_measurement(s(0), s(1), s(2), kSigmas, c, kSensor));
      const Mat3 S = kSigmas.cwiseProduct(kSigmas).asDiagonal();
      const auto avg = averaged_truth_conditioned_moments<3, 3>(s, S, 8, [c](const Vec3& m) { return enu_of(m, c); });
      // E_t|m[p(t)] by its own cubature, so that the average bias is E_t[E[p(m')|t]] - E_t[p(t)].
      const auto truth = gauss_hermite_moments<3, 3>(s, S, 8, [c](const Vec3& t) { return enu_of(t, c); });
      const Vec3 average_bias = avg.mean - truth.mean;
      CHECK((got.value.head<3>() - kSensor - (enu_of(s, c) - average_bias)).norm() < 1e-8 * s(0));
      CHECK(relative_difference(Mat3(got.covariance), avg.covariance) < 1e-8);
    }
  }
}

// range-rate cross-covariance is the average true covariance of (p(m), range rate) (cubature)
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
      y << enu_of(mm.head<3>(), c), mm(3);
      return y;
    });
    CHECK(relative_difference(Vec3(got.covariance.block<3, 1>(0, 3)), Vec3(ref.covariance.block<3, 1>(0, 3))) < 1e-8);
    CHECK(got.value(3) == 35.0);
  }
}

// In the horizontal plane with no elevation error the 3-D conversion must reduce to Lerro &
// Bar-Shalom's published 2-D expressions (azimuth θ from x toward y), written here in their
// cosh/sinh form, independently of conversion_moments.hpp.
TEST_CASE("reduces to Lerro and Bar-Shalom 2-D expressions") {
  auto conv = make(kType);
  OneShot out;
  const double r = 15e3, th = 0.9, sr = 20.0, st = 0.15;
  const Measurement got = out.convert(
      *conv, spherical_measurement(r, th, 0.0, Vec3(sr, st, 0.0), AzimuthConvention::XCounterClockwise));
  const double s2 = st * st, sr2 = sr * sr, c = std::cos(th), s = std::sin(th);
  const double k = std::exp(-s2) - std::exp(-s2 / 2);
  const Vec3 mean(r * c - r * c * k, r * s - r * s * k, 0.0);
  const double e2 = std::exp(-2 * s2);
  Mat3 R = Mat3::Zero();
  R(0, 0) = r * r * e2 * (c * c * (std::cosh(2 * s2) - std::cosh(s2)) + s * s * (std::sinh(2 * s2) - std::sinh(s2))) +
            sr2 * e2 * (c * c * (2 * std::cosh(2 * s2) - std::cosh(s2)) + s * s * (2 * std::sinh(2 * s2) - std::sinh(s2)));
  R(1, 1) = r * r * e2 * (s * s * (std::cosh(2 * s2) - std::cosh(s2)) + c * c * (std::sinh(2 * s2) - std::sinh(s2))) +
            sr2 * e2 * (s * s * (2 * std::cosh(2 * s2) - std::cosh(s2)) + c * c * (2 * std::sinh(2 * s2) - std::sinh(s2)));
  R(0, 1) = R(1, 0) = s * c * std::exp(-4 * s2) * (sr2 + (r * r + sr2) * (1 - std::exp(s2)));
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
