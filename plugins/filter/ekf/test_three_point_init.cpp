// Purpose: tests of the three-point initialisation: the symmetric paper-000 P0 against the printed matrix and against sample statistics.
#include "estimation/three_point_init.hpp"

#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

using namespace trackflow;

// paper 000 P0: symmetric positive definite, equal to the printed matrix except its (3,1) typo
TEST_CASE("paper 000 P0 is PD and matches the printed matrix") {
  const double s2 = 4.0, T = 0.025;
  const Eigen::Matrix3d P = cartesian_filter::paper000_axis_covariance(s2, T, T);
  Eigen::Matrix3d printed;
  printed << s2, s2 / T, s2 / (T * T),                                //
      s2 / T, 2 * s2 / (T * T), 3 * s2 / (T * T * T),                 //
      2 * s2 / (T * T), 3 * s2 / (T * T * T), 6 * s2 / (T * T * T * T);
  CHECK_FALSE(printed.isApprox(printed.transpose()));
  Eigen::Matrix3d expected = printed;
  expected(2, 0) = s2 / (T * T);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) CHECK(P(i, j) == Approx(expected(i, j)).epsilon(1e-12));
  CHECK((P - P.transpose()).norm() == 0.0);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(P);
  CHECK(eig.eigenvalues().minCoeff() > 0.0);
  CHECK(Eigen::LLT<Eigen::Matrix3d>(P).info() == Eigen::Success);
}

// three-point differences recover a quadratic exactly in position and acceleration, and P0 matches sample
// covariance
TEST_CASE("three-point init is exact and P0 matches samples") {
  const double T1 = 0.1, T2 = 0.15, p0 = 100, v0 = 30, a0 = -4;
  auto p = [&](double t) { return p0 + v0 * t + 0.5 * a0 * t * t; };
  const double t3 = T1 + T2;
  const Eigen::Matrix3d A = cartesian_filter::three_point_differences(T1, T2);
  const Eigen::Vector3d s = A * Eigen::Vector3d(p(0), p(T1), p(t3));
  CHECK(s(0) == Approx(p(t3)));
  CHECK(s(2) == Approx(a0));
  // Backward difference: the velocity at the middle of the last interval (lags a T2 / 2).
  CHECK(s(1) == Approx(v0 + a0 * (t3 - T2 / 2)));

  const double sigma = 3.0;
  const Eigen::Matrix3d P = cartesian_filter::paper000_axis_covariance(sigma * sigma, T1, T2);
  Rng rng(5);
  const int n = 40000;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d e = A * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()) * sigma;
    C += e * e.transpose();
  }
  C /= n;
  // Sample covariance: entry error ~ sqrt((P_ii P_jj + P_ij^2) / n) <= sqrt(2/n) ~ 0.7 % of the scale.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) CHECK(std::abs(C(i, j) - P(i, j)) < 4 * std::sqrt(2.0 / n) * std::sqrt(P(i, i) * P(j, j)));
}
