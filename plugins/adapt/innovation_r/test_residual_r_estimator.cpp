// Purpose: tests of the moving-average R estimator and its positive-definite floor, independent of any filter.
#include "residual_r_estimator.hpp"

#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

using namespace trackflow;
using adapt::apply_floor;
using adapt::EstimatorSettings;
using adapt::ResidualREstimator;

namespace {

// Smallest eigenvalue of nominal^-1/2 R nominal^-1/2 (R >= c nominal  <=>  this >= c).
double min_generalised_eigenvalue(const Mat3& R, const Mat3& nominal) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> es(R, nominal);
  return es.eigenvalues().minCoeff();
}

Mat3 anisotropic_nominal() {
  Mat3 A;
  A << 1.0, 0.3, -0.2, 0.0, 1.0, 0.5, 0.1, 0.0, 1.0;
  return A * Vec3(9.0, 100.0, 36.0).asDiagonal() * A.transpose();
}

}  // namespace

// the moving average follows eq 31 in closed form for a constant single-step estimate
TEST_CASE("moving average follows eq 31 in closed form") {
  EstimatorSettings s;
  s.window = 7;
  s.warmup = 0;
  s.floor_ratio = 0.0;
  ResidualREstimator est(s);
  const Mat3 R0 = anisotropic_nominal();
  est.start(R0);
  REQUIRE(est.adapting());
  const Vec3 dz(2.0, -1.0, 0.5);
  const Mat3 P = Vec3(0.5, 0.25, 1.0).asDiagonal();
  const Mat3 Rs = dz * dz.transpose() + P;
  const int n = 40;
  for (int k = 0; k < n; ++k) est.update(dz, P, R0);
  // R_n = Rs + (1 - 1/L)^n (R_0 - Rs)
  const Mat3 expected = Rs + std::pow(1.0 - 1.0 / 7.0, n) * (R0 - Rs);
  CHECK((est.estimate() - expected).norm() < 1e-12 * expected.norm());
  CHECK((est.estimate() - est.estimate().transpose()).norm() == 0.0);
}

TEST_CASE("eq 28 as printed subtracts the posterior covariance") {
  EstimatorSettings s;
  s.window = 1;  // R_k = R_s
  s.warmup = 0;
  s.floor_ratio = 0.0;
  s.floor_sigma = 1e-9;
  s.add_posterior = false;
  ResidualREstimator est(s);
  est.start(Mat3::Identity() * 100.0);
  const Vec3 dz(3.0, 0.0, 0.0);
  est.update(dz, Mat3::Identity(), Mat3::Identity() * 100.0);
  CHECK(est.estimate()(0, 0) == Approx(9.0 - 1.0));
  // (0 - 1) in y and z: negative, so the absolute floor takes over.
  CHECK(est.estimate()(1, 1) == Approx(1e-18).margin(1e-20));
}

// warm-up: the estimate is the latest nominal R until `warmup` residuals have been seen
TEST_CASE("warm-up returns the nominal R") {
  EstimatorSettings s;
  s.warmup = 3;
  ResidualREstimator est(s);
  CHECK_FALSE(est.started());
  const Mat3 N = anisotropic_nominal();
  est.start(N);
  CHECK_FALSE(est.adapting());
  for (int k = 0; k < 3; ++k) {
    est.update(Vec3(100, 100, 100), Mat3::Identity(), N * (k + 2));
    CHECK((est.estimate() - N * (k + 2)).norm() < 1e-12 * N.norm());
  }
  CHECK(est.adapting());
  est.update(Vec3(100, 100, 100), Mat3::Identity(), N);
  CHECK(est.estimate()(0, 0) > 4.0 * N(0, 0));
}

TEST_CASE("apply_floor raises only eigenvalues below floors") {
  const Mat3 N = anisotropic_nominal();
  SECTION("above both floors: unchanged") {
    Mat3 R = 2.0 * N;
    CHECK_FALSE(apply_floor(R, N, 0.1, 1e-3));
    CHECK(R == 2.0 * N);
  }
  SECTION("relative floor in the nominal's metric") {
    // R = N^1/2 diag(4, 1e-6, 0.5) N^1/2: only the middle generalised eigenvalue is below 0.01.
    const Eigen::LLT<Mat3> llt(N);
    const Mat3 L = llt.matrixL();
    Mat3 R = L * Vec3(4.0, 1e-6, 0.5).asDiagonal() * L.transpose();
    CHECK(apply_floor(R, N, 0.1, 1e-6));
    const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> es(R, N);
    CHECK(es.eigenvalues()(0) == Approx(0.01).epsilon(1e-9));
    CHECK(es.eigenvalues()(1) == Approx(0.5).epsilon(1e-9));
    CHECK(es.eigenvalues()(2) == Approx(4.0).epsilon(1e-9));
  }
  SECTION("absolute floor when the nominal is not positive definite") {
    Mat3 R = Mat3::Zero();
    R(0, 0) = -5.0;
    CHECK(apply_floor(R, Mat3::Zero(), 0.1, 0.01));
    const Eigen::SelfAdjointEigenSolver<Mat3> es(R);
    CHECK(es.eigenvalues().minCoeff() == Approx(1e-4).epsilon(1e-9));
    CHECK(es.eigenvalues().maxCoeff() == Approx(1e-4).epsilon(1e-9));
  }
}

// the floor keeps R-hat positive definite against adversarial residuals
TEST_CASE("floor keeps R-hat PD against adversarial residuals") {
  const Mat3 N = anisotropic_nominal();
  Rng rng(99);
  for (bool add : {true, false}) {
    EstimatorSettings s;
    s.window = 5;
    s.warmup = 0;
    s.add_posterior = add;
    s.floor_ratio = 0.2;
    s.floor_sigma = 0.05;
    ResidualREstimator est(s);
    est.start(N);
    int violations = 0;
    for (int k = 0; k < 20000; ++k) {
      Vec3 dz = Vec3::Zero();
      Mat3 P = Mat3::Zero();
      switch (k % 4) {
        case 0: break;  // a perfect fit: R_s = 0 (add) pulls R-hat to zero
        case 1: P = 1e6 * N; break;  // huge posterior: R_s = -1e6 N (subtract) is negative definite
        case 2: dz = 1e4 * Vec3(rng.normal(), rng.normal(), rng.normal()); break;  // outlier, rank one
        case 3: dz = Vec3(1e-8, 0, 0); P = -1e3 * Mat3::Identity(); break;  // not even a covariance
      }
      est.update(dz, P, N);
      const Mat3& R = est.estimate();
      const Eigen::SelfAdjointEigenSolver<Mat3> es(R);
      // Up to rounding relative to the largest eigenvalue (outliers push it to ~1e8 m2).
      const double rounding = 1e-12 * es.eigenvalues().maxCoeff();
      const bool ok = R.allFinite() && (R - R.transpose()).norm() == 0.0 &&
                      es.eigenvalues().minCoeff() >= 0.05 * 0.05 - rounding &&
                      min_generalised_eigenvalue(R, N) >= 0.04 - rounding / 9.0;
      violations += !ok;
    }
    INFO("add_posterior " << add);
    CHECK(violations == 0);
  }
}
