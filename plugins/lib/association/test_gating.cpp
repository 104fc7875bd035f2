// Purpose: tests of the gating header: NIS against an explicit inverse, the azimuth residual wrapped, the log-likelihood against the Gaussian density, a non-positive-definite S refused.
#include <catch2/catch.hpp>

#include "association/gating.hpp"

#include <Eigen/LU>

#include <cmath>
#include <numbers>

using namespace trackflow;

namespace {

PredictedMeasurement predicted(const Eigen::Vector3d& z, const Eigen::Matrix3d& S) {
  PredictedMeasurement p;
  p.z = z;
  p.S = S;
  set_log_det(p);
  return p;
}

}  // namespace

TEST_CASE("NIS and likelihood equal the direct forms") {
  Eigen::Matrix3d A;
  A << 4, 1, 0.5, 1, 3, 0.2, 0.5, 0.2, 2;
  const PredictedMeasurement p = predicted(Eigen::Vector3d(10, 20, 30), A);
  association::PredictedGate g;
  REQUIRE(g.set(p, Frame::Cartesian));
  MeasVec v(3);
  v << 11.5, 18.0, 30.7;
  const Eigen::Vector3d nu = Eigen::Vector3d(v) - Eigen::Vector3d(10, 20, 30);
  const double direct = nu.dot(A.inverse() * nu);
  CHECK(g.nis(v) == Approx(direct).epsilon(1e-13));
  const double density = std::exp(-0.5 * direct) / std::sqrt(std::pow(2 * std::numbers::pi, 3) * A.determinant());
  CHECK(g.log_likelihood(g.nis(v)) == Approx(std::log(density)).epsilon(1e-13));
}

TEST_CASE("azimuth residual is wrapped") {
  const PredictedMeasurement p = predicted(Eigen::Vector3d(1000, std::numbers::pi - 0.01, 0.1), Eigen::Matrix3d::Identity() * 1e-4);
  association::PredictedGate g;
  REQUIRE(g.set(p, Frame::Spherical));
  MeasVec v(3);
  v << 1000, -std::numbers::pi + 0.01, 0.1;
  CHECK(g.nis(v) == Approx(0.02 * 0.02 / 1e-4).epsilon(1e-9));
  association::PredictedGate cartesian;
  REQUIRE(cartesian.set(p, Frame::Cartesian));  // no wrap: the residual is ~2 pi
  CHECK(cartesian.nis(v) > 1e5);
}

TEST_CASE("a non-positive-definite S takes nothing") {
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(2, 2) = -1.0;
  PredictedMeasurement p;
  p.z = Eigen::Vector3d::Zero();
  p.S = S;
  set_log_det(p);
  association::PredictedGate g;
  CHECK_FALSE(g.set(p, Frame::Cartesian));
}
