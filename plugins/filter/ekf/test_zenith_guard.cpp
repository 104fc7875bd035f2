// Purpose: tests of the zenith guard shared by filter.ekf and filter.ukf (zenith_guard.hpp) and of the iterated update for a prior much wider than the measurement (ekf_radar_update.hpp).
#include "estimation/ekf_radar_update.hpp"
#include "estimation/radar_filter_test_support.hpp"
#include "estimation/zenith_guard.hpp"

#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

using namespace trackflow;
using cartesian_filter::EkfInnovation;
using cartesian_filter::EkfOutcome;

namespace {
// State [x y z vx vy vz]: the radar update's indices are the identity.
constexpr int kIdx[6] = {0, 1, 2, 3, 4, 5};
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Mat6 diagonal(double pos_var, double vel_var) {
  Mat6 P = Mat6::Zero();
  P.diagonal() << pos_var, pos_var, pos_var, vel_var, vel_var, vel_var;
  return P;
}
}  // namespace

// one test for both filters: the EKF's angle_curvature_variance flag, plus straight overhead
TEST_CASE("zenith guard: no azimuth where filter.ekf drops it") {
  const Eigen::Matrix2d Ph = 4.0 * Eigen::Matrix2d::Identity();  // 2 m per axis: 3 sigma of the trace is 8.5 m
  for (double rho : {0.0, 1.0, 8.0, 8.6, 50.0, 5000.0}) {
    INFO(rho);
    const Vec3 d(rho, 0.0, 10e3);
    const bool ekf = rho < kZenithFraction * d.norm() ||
                     ekf::angle_curvature_variance(d, Ph, kZenithFraction * d.norm()).azimuth_unusable;
    CHECK(cartesian_filter::azimuth_unusable(d, Ph) == ekf);
    CHECK(cartesian_filter::azimuth_unusable(d, Ph) == (rho < 8.5));
  }
  // Straight overhead with no uncertainty at all: still no azimuth.
  CHECK(cartesian_filter::azimuth_unusable(Vec3(0, 0, 10e3), Eigen::Matrix2d::Zero()));
  CHECK_FALSE(cartesian_filter::azimuth_unusable(Vec3(1, 0, 10e3), Eigen::Matrix2d::Zero()));
}

// the dropped azimuth: zero innovation, decorrelated R that keeps its own variance
TEST_CASE("zenith guard: a dropped azimuth has no innovation") {
  Eigen::Vector4d nu(1, 2, 3, 4);
  Eigen::Matrix4d R = Eigen::Matrix4d::Constant(0.5);
  R.diagonal() << 100, 1e-6, 2e-6, 0.25;
  cartesian_filter::drop_azimuth_noise<4>(nu, R);
  CHECK(nu == Eigen::Vector4d(1, 0, 3, 4));
  CHECK(R(1, 1) == 1e-6);
  for (int k : {0, 2, 3}) {
    CHECK(R(1, k) == 0.0);
    CHECK(R(k, 1) == 0.0);
  }
  CHECK(R(0, 2) == 0.5);
  R(1, 1) = 0.0;
  cartesian_filter::drop_azimuth_noise<4>(nu, R);
  CHECK(R(1, 1) == 1.0);  // an azimuth without variance gets one (S stays positive definite)
}

// the horizontal block in a tilted sensor's axes
TEST_CASE("zenith guard: horizontal covariance in sensor axes") {
  Mat6 P = diagonal(1.0, 1.0);
  P(2, 2) = 100.0;  // vertical in the frame
  Measurement m;
  CHECK(cartesian_filter::horizontal_covariance<6>(P, kIdx, m).isApprox(Eigen::Matrix2d::Identity()));
  m.sensor_level = false;
  // A sensor whose "up" is the frame's x: the frame's z is horizontal for it.
  m.sensor_axes << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  const Eigen::Matrix2d Ph = cartesian_filter::horizontal_covariance<6>(P, kIdx, m);
  CHECK(Ph.trace() == Approx(101.0));
}

// a prior 18 km wide on a measurement 10 m wide: iterated to the measured point
TEST_CASE("iterated update: a very wide prior ends at the measurement") {
  const Vec3 truth(5000.0, 7000.0, 3000.0), sensor = Vec3::Zero();
  filter_test::RadarNoise noise;
  const Measurement m = filter_test::radar(1.0, truth, Vec3::Zero(), sensor, noise, nullptr, false);
  const Eigen::Matrix3d R = m.covariance.topLeftCorner<3, 3>();
  Vec6 x0 = Vec6::Zero();
  x0.head<3>() = truth + Vec3(3000.0, -2000.0, 1000.0);  // the prediction 3.7 km off
  const Mat6 wide = diagonal(3.3e8, 1e11);               // q = 1e12 m2/s3 over 0.1 s
  REQUIRE(cartesian_filter::prior_much_wider<6, 3>(x0, wide, kIdx, m, R));
  CHECK_FALSE(cartesian_filter::prior_much_wider<6, 3>(x0, diagonal(100.0, 100.0), kIdx, m, R));

  Vec6 x = x0;
  Mat6 P = wide;
  EkfInnovation<3> in;
  REQUIRE(cartesian_filter::ekf_radar_update<6, 3>(x, P, kIdx, m, R, true, in) == EkfOutcome::Used);
  CHECK(in.relinearised);
  CHECK_FALSE(in.azimuth_dropped);  // far from the zenith, whatever the prior's width
  CHECK((x.head<3>() - truth).norm() < 0.1);
  // The posterior is the measurement's: metres, not kilometres.
  CHECK(P.topLeftCorner<3, 3>().trace() < 1e3);

  // The plain EKF step from the same prediction lands tens of metres off (the linearisation about
  // a point 3.7 km away), and the old rule dropped the azimuth on this prior.
  Vec6 xt = x0;
  Mat6 Pt = wide;
  EkfInnovation<3> plain;
  REQUIRE(cartesian_filter::ekf_radar_update<6, 3>(xt, Pt, kIdx, m, R, false, plain) == EkfOutcome::Used);
  CHECK_FALSE(plain.relinearised);
  CHECK((xt.head<3>() - truth).norm() > 10.0);
  EkfInnovation<3> old;
  Eigen::Matrix<double, 6, 3> PHt;
  REQUIRE(cartesian_filter::ekf_radar_linearise<6, 3>(x0, wide, kIdx, m, R, true, old, PHt) == EkfOutcome::Used);
  CHECK(old.azimuth_dropped);
}

// an ordinary prior is not iterated: the update is the one it always was, to the bit
TEST_CASE("iterated update: an ordinary prior is not iterated") {
  const Vec3 truth(5000.0, 7000.0, 3000.0);
  const Measurement m = filter_test::radar(1.0, truth, Vec3::Zero(), Vec3::Zero(), {}, nullptr, false);
  const Eigen::Matrix3d R = m.covariance.topLeftCorner<3, 3>();
  Vec6 x = Vec6::Zero();
  x.head<3>() = truth + Vec3(5, -3, 2);
  Mat6 P = diagonal(100.0, 25.0);
  Vec6 x1 = x;
  Mat6 P1 = P;
  EkfInnovation<3> a, b;
  REQUIRE(cartesian_filter::ekf_radar_update<6, 3>(x, P, kIdx, m, R, true, a) == EkfOutcome::Used);
  Eigen::Matrix<double, 6, 3> PHt;
  REQUIRE(cartesian_filter::ekf_radar_linearise<6, 3>(x1, P1, kIdx, m, R, true, b, PHt) == EkfOutcome::Used);
  double nis = 0.0;
  REQUIRE(joseph_update_cross<6, 3>(x1, P1, b.nu, PHt, b.S, nis));
  CHECK_FALSE(a.relinearised);
  CHECK(x == x1);
  CHECK(P == P1);
}
