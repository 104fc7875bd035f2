// Purpose: tests of the decoupled-filter math against a full 6-state Kalman filter and the exact conversion Jacobian.
#include "decoupled_cv.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <limits>

using namespace trackflow;
using decoupled::DecoupledCv;
using decoupled::Mat2;

namespace {

using Mat36 = Eigen::Matrix<double, 3, 6>;

Mat36 position_selector() {
  Mat36 H = Mat36::Zero();
  for (int a = 0; a < 3; ++a) H(a, decoupled::pos(a)) = 1.0;
  return H;
}

Mat2 random_spd2(Rng& rng, double scale) {
  Mat2 A;
  A << rng.normal(), rng.normal(), rng.normal(), rng.normal();
  return scale * (A * A.transpose() + 0.1 * Mat2::Identity());
}

DecoupledCv random_state(Rng& rng) {
  DecoupledCv f;
  Mat3 D;
  REQUIRE(decoupled::line_of_sight_frame(Vec3(rng.normal(), rng.normal(), rng.normal()) * 1000.0, D));
  f.D = D;
  for (int i = 0; i < 3; ++i) f.P[i] = random_spd2(rng, 10.0 * (i + 1));
  for (int i = 0; i < 6; ++i) f.x(i) = 100.0 * rng.normal();
  return f;
}

// Full Kalman gain P H' (H P H' + R)^-1, computed with dynamic-size Eigen, independently of the header.
Eigen::MatrixXd full_gain(const Mat6& P, const Mat3& R) {
  const Eigen::MatrixXd H = position_selector();
  const Eigen::MatrixXd S = H * P * H.transpose() + Eigen::MatrixXd(R);
  return P * H.transpose() * S.inverse();
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

// line-of-sight frame is a rotation that diagonalises the classical converted covariance
TEST_CASE("LOS frame rotation diagonalises converted R") {
  Rng rng(11);
  for (int k = 0; k < 200; ++k) {
    const double r = 100.0 + 50e3 * rng.uniform();
    const double az = wrap_angle(7.0 * rng.normal());
    const double el = 1.4 * (2.0 * rng.uniform() - 1.0);
    const double sr = 1.0 + 10.0 * rng.uniform(), sa = 1e-3 * (0.1 + rng.uniform()), se = 1e-3 * (0.1 + rng.uniform());
    for (auto convention : {AzimuthConvention::XCounterClockwise, AzimuthConvention::NorthClockwise}) {
      const Vec3 d = spherical_to_enu(r, az, el, convention);
      Mat3 D;
      REQUIRE(decoupled::line_of_sight_frame(d, D));
      CHECK((D.transpose() * D - Mat3::Identity()).norm() < 1e-12);
      CHECK(D.determinant() == Approx(1.0).epsilon(1e-12));
      CHECK((D.col(0) - d / r).norm() < 1e-12);
      // J R_s J' from the geometry header's exact Jacobian versus D diag(...) D'.
      const Mat3 J = spherical_to_enu_jacobian(r, az, el, convention);
      const Mat3 Rc = J * Vec3(sr * sr, sa * sa, se * se).asDiagonal() * J.transpose();
      const Vec3 expected(sr * sr, std::pow(r * std::cos(el) * sa, 2), std::pow(r * se, 2));
      const Mat3 Rbar = D.transpose() * Rc * D;
      CHECK((Rbar.diagonal() - expected).norm() < 1e-9 * expected.norm());
      Mat3 off = Rbar;
      off.diagonal().setZero();
      CHECK(off.norm() < 1e-9 * expected.norm());
    }
  }
  Mat3 D = Mat3::Identity();
  CHECK_FALSE(decoupled::line_of_sight_frame(Vec3(0, 0, 500), D));  // straight overhead
  CHECK_FALSE(decoupled::line_of_sight_frame(Vec3::Zero(), D));
  CHECK(D == Mat3::Identity());
}

// decoupled gain equals the full Kalman gain when R is diagonal in the decoupled frame
TEST_CASE("gain equals full Kalman gain for diagonal R") {
  Rng rng(5);
  for (int k = 0; k < 100; ++k) {
    DecoupledCv f = random_state(rng);
    const Vec3 r(1.0 + 20.0 * rng.uniform(), 1.0 + 20.0 * rng.uniform(), 1.0 + 20.0 * rng.uniform());
    const Mat3 R = f.D * r.asDiagonal() * f.D.transpose();
    Mat6 P;
    f.cartesian_covariance(P);
    CHECK(rel(f.gain(R), full_gain(P, R)) < 1e-10);

    // The whole update agrees with the SDK's full Joseph update on the Cartesian covariance.
    Vec6 x = f.x;
    Mat6 Pfull = P;
    const Vec3 z(f.x(0) + 5 * rng.normal(), f.x(2) + 5 * rng.normal(), f.x(4) + 5 * rng.normal());
    Mat3 S;
    double nis_full = 0;
    REQUIRE(joseph_update<6, 3>(x, Pfull, Vec3(z - position_selector() * x), position_selector(), R, S, nis_full));
    decoupled::UpdateResult u;
    REQUIRE(f.update(z, R, u));
    Mat6 P1;
    f.cartesian_covariance(P1);
    CHECK((f.x - x).norm() < 1e-9 * x.norm());
    CHECK(rel(P1, Pfull) < 1e-10);
    CHECK(u.nis == Approx(nis_full).epsilon(1e-10));
    CHECK(rel(u.innovation_covariance, S) < 1e-12);
  }
}

// with R correlated in the decoupled frame the gain uses its diagonal, an error first order in the
// correlation
TEST_CASE("correlated R: gain error is first order") {
  Rng rng(8);
  for (int k = 0; k < 50; ++k) {
    DecoupledCv f = random_state(rng);
    const Vec3 r(4.0 + 20.0 * rng.uniform(), 4.0 + 20.0 * rng.uniform(), 4.0 + 20.0 * rng.uniform());
    auto correlated = [&](double rho) {
      Mat3 Rbar = r.asDiagonal();
      Rbar(0, 1) = Rbar(1, 0) = rho * std::sqrt(r(0) * r(1));
      Rbar(1, 2) = Rbar(2, 1) = -0.5 * rho * std::sqrt(r(1) * r(2));
      return Mat3(f.D * Rbar * f.D.transpose());
    };
    Mat6 P;
    f.cartesian_covariance(P);
    const Mat3 R_diagonal_part = f.D * r.asDiagonal() * f.D.transpose();
    const double rho = 0.2;
    const Mat3 R = correlated(rho);
    // The decoupled gain is exactly the full gain for the decoupled-frame diagonal of R ...
    CHECK(rel(f.gain(R), full_gain(P, R_diagonal_part)) < 1e-10);
    // ... so it differs from the full gain for R itself, by an amount proportional to rho.
    const double d1 = (f.gain(R) - full_gain(P, R)).norm();
    const double d2 = (f.gain(correlated(rho / 2)) - full_gain(P, correlated(rho / 2))).norm();
    CHECK(d1 > 1e-6 * full_gain(P, R).norm());
    CHECK(d1 / d2 == Approx(2.0).epsilon(0.15));
    CHECK(d1 < rho * full_gain(P, R).norm());
  }
}

// prediction of the per-axis blocks equals F P F' + Q of the Cartesian covariance (isotropic Q)
TEST_CASE("per-axis prediction equals Cartesian F P F' + Q") {
  Rng rng(3);
  DecoupledCv f = random_state(rng);
  Mat6 P0;
  f.cartesian_covariance(P0);
  const double T = 0.37, q = 2.5;
  const Mat2 Qa = ConstantVelocity::axis_noise_continuous(T, q);
  ConstantVelocity::Matrix F, Q;
  ConstantVelocity::transition(T, F);
  ConstantVelocity::block_diagonal(Qa, Q);
  const Vec6 x0 = f.x;
  f.predict(T, Qa);
  Mat6 P1;
  f.cartesian_covariance(P1);
  CHECK(rel(P1, F * P0 * F.transpose() + Q) < 1e-12);
  CHECK((f.x - F * x0).norm() < 1e-12 * x0.norm());
}

// reframing is exact for axis permutations, keeps the trace, and keeps the block diagonal of the rotated
// covariance
TEST_CASE("reframing keeps trace and rotated block diagonal") {
  Rng rng(21);
  DecoupledCv f = random_state(rng);
  Mat6 P0;
  f.cartesian_covariance(P0);

  // A cyclic permutation of the axes (still right-handed): nothing is dropped.
  DecoupledCv g = f;
  Mat3 permuted;
  permuted << f.D.col(1), f.D.col(2), f.D.col(0);
  g.reframe(permuted);
  Mat6 P1;
  g.cartesian_covariance(P1);
  CHECK(rel(P1, P0) < 1e-12);
  CHECK((g.P[0] - f.P[1]).norm() < 1e-12 * f.P[1].norm());

  // A general small rotation: the new blocks are the diagonal blocks of D2' P D2 in the new frame.
  Mat3 next;
  REQUIRE(decoupled::line_of_sight_frame(f.D.col(0) + 0.3 * f.D.col(1) - 0.2 * f.D.col(2), next));
  DecoupledCv h = f;
  h.reframe(next);
  const Mat6 expressed = h.d2().transpose() * P0 * h.d2();
  for (int i = 0; i < 3; ++i) CHECK((h.P[i] - expressed.block<2, 2>(2 * i, 2 * i)).norm() < 1e-10 * P0.norm());
  Mat6 P2;
  h.cartesian_covariance(P2);
  CHECK(P2.trace() == Approx(P0.trace()).epsilon(1e-12));
}

// an R with a negative variance in the decoupled frame is refused and changes nothing
TEST_CASE("negative decoupled variance in R is refused") {
  Rng rng(2);
  DecoupledCv f = random_state(rng);
  const DecoupledCv before = f;
  decoupled::UpdateResult u;
  const Mat3 R = f.D * Vec3(4.0, -1.0, 4.0).asDiagonal() * f.D.transpose();
  CHECK_FALSE(f.update(Vec3(1, 2, 3), R, u));
  CHECK(f.x == before.x);
  CHECK(f.P[1] == before.P[1]);
  Mat3 nan_R = Mat3::Identity();
  nan_R(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(f.update(Vec3(1, 2, 3), nan_R, u));
  CHECK(f.x == before.x);
}
