// Purpose: tests of the IMM arithmetic (imm_mixing.hpp) against hand computations: mixing with equal and unequal state sizes, transition-matrix checks, mixing weights, log-domain probabilities.
#include "imm_mixing.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace trackflow;
using namespace trackflow::imm;

namespace {
// Common-state indices: x 0, vx 1, ax 2 (then y, z).
constexpr int kX = 0, kVX = 1, kAX = 2;
}  // namespace

TEST_CASE("mixing two modes of equal size matches a hand computation") {
  CommonEstimate m[2];
  m[0].x(kX) = 1.0;
  m[0].P = MatC::Identity();
  m[0].has_acceleration = true;
  m[1].x(kX) = 3.0;
  m[1].P = 2.0 * MatC::Identity();
  m[1].has_acceleration = true;
  const double w[2] = {0.25, 0.75};
  VecC x;
  MatC P;
  mix(m, w, 2, m[0].x, m[0].P, x, P);
  CHECK(x(kX) == Approx(2.5));
  // 0.25 (1 + 1.5^2) + 0.75 (2 + 0.5^2) = 0.8125 + 1.6875
  CHECK(P(kX, kX) == Approx(2.5));
  CHECK(P(kAX, kAX) == Approx(1.75));
  CHECK(P(4, 4) == Approx(1.75));
  CHECK(P(kX, kVX) == 0.0);
  CHECK((P - P.transpose()).norm() == 0.0);
}

TEST_CASE("a CV mode borrows the receiving acceleration") {
  // CV: 6 states [x vx y vy z vz]; x = 10, vx = 1, P = I.
  Eigen::Matrix<double, 6, 1> xcv = Eigen::Matrix<double, 6, 1>::Zero();
  xcv(0) = 10.0;
  xcv(1) = 1.0;
  const Eigen::Matrix<double, 6, 6> Pcv = Eigen::Matrix<double, 6, 6>::Identity();
  CommonEstimate m[2];
  to_common<2>(xcv, Pcv, m[0]);
  REQUIRE_FALSE(m[0].has_acceleration);
  CHECK(m[0].x(kX) == 10.0);
  CHECK(m[0].x(kVX) == 1.0);
  CHECK(m[0].P(3, 3) == 1.0);  // y
  // CA: x = 12, vx = 1, ax = 4, P = 2 I with cov(x, ax) = 0.3.
  Eigen::Matrix<double, 9, 1> xca = Eigen::Matrix<double, 9, 1>::Zero();
  xca(kX) = 12.0;
  xca(kVX) = 1.0;
  xca(kAX) = 4.0;
  Eigen::Matrix<double, 9, 9> Pca = 2.0 * Eigen::Matrix<double, 9, 9>::Identity();
  Pca(kX, kAX) = Pca(kAX, kX) = 0.3;
  to_common<3>(xca, Pca, m[1]);
  const double w[2] = {0.5, 0.5};
  VecC x;
  MatC P;
  mix(m, w, 2, m[1].x, m[1].P, x, P);
  CHECK(x(kX) == Approx(11.0));
  CHECK(x(kAX) == Approx(4.0));      // no pull towards zero
  CHECK(P(kAX, kAX) == Approx(2.0));  // 0.5 * 2 (borrowed) + 0.5 * 2, no spread
  CHECK(P(kX, kX) == Approx(2.5));    // 0.5 (1 + 1) + 0.5 (2 + 1)
  CHECK(P(kX, kAX) == Approx(0.15));  // only the CA mode's own cross term
  CHECK(P(kVX, kVX) == Approx(1.5));
  // A CV receiver (its own zero acceleration as the reference): the same position and velocity.
  VecC xr;
  MatC Pr;
  mix(m, w, 2, m[0].x, m[0].P, xr, Pr);
  CHECK(Pr(kX, kX) == Approx(2.5));
  CHECK(Pr(kX, kAX) == Approx(2.15));  // 0.5 * 0.3 + 0.5 (1 * 2) + 0.5 (-1 * -2): zero acceleration lent
  Eigen::Matrix<double, 6, 1> back;
  Eigen::Matrix<double, 6, 6> Pback;
  from_common<2>(xr, Pr, back, Pback);
  CHECK(back(0) == Approx(11.0));
  CHECK(back(1) == Approx(1.0));
  CHECK(Pback(0, 0) == Approx(2.5));
  CHECK(Pback(2, 2) == Approx(1.5));  // y: 0.5 * 1 + 0.5 * 2
}

TEST_CASE("transition matrix checks") {
  CHECK(check_transition({0.9, 0.1, 0.2, 0.8}, 2).empty());
  CHECK(check_transition({0.9, 0.1, 0.2, 0.7}, 2).find("row 2") != std::string::npos);
  CHECK(check_transition({0.9, 0.1, 0.2}, 2).find("4") != std::string::npos);
  CHECK(check_transition({1.1, -0.1, 0.2, 0.8}, 2).find("not a probability") != std::string::npos);
  CHECK(check_transition({1, 0, 0, 0, 1, 0, 0, 0, 1}, 3).empty());
}

TEST_CASE("mixing weights and predicted probabilities by hand") {
  const double pi[4] = {0.9, 0.1, 0.2, 0.8};
  const double mu[2] = {0.5, 0.5};
  double c[2], w[kMaxModes][kMaxModes];
  mixing_weights(pi, mu, 2, c, w);
  CHECK(c[0] == Approx(0.55));
  CHECK(c[1] == Approx(0.45));
  CHECK(w[0][0] == Approx(0.45 / 0.55));
  CHECK(w[0][1] == Approx(0.10 / 0.55));
  CHECK(w[1][0] == Approx(0.05 / 0.45));
  CHECK(w[1][0] + w[1][1] == Approx(1.0));
}

TEST_CASE("mode probabilities in the log domain sum to 1") {
  const double c[3] = {0.5, 0.25, 0.25};
  double mu[3];
  const double ll[3] = {0.0, std::log(4.0), std::log(2.0)};
  REQUIRE(update_probabilities(c, ll, 3, mu));
  // 0.5 : 1 : 0.5
  CHECK(mu[0] == Approx(0.25));
  CHECK(mu[1] == Approx(0.5));
  CHECK(mu[2] == Approx(0.25));
  // Likelihoods that underflow exp(): the ratios survive.
  const double tiny[3] = {-2e4, -2e4 - std::log(2.0), -std::numeric_limits<double>::infinity()};
  REQUIRE(update_probabilities(c, tiny, 3, mu));
  CHECK(mu[0] == Approx(0.8));
  CHECK(mu[1] == Approx(0.2));
  CHECK(mu[2] == 0.0);
  CHECK(mu[0] + mu[1] + mu[2] == Approx(1.0).epsilon(1e-15));
  const double none[3] = {-INFINITY, -INFINITY, -INFINITY};
  CHECK_FALSE(update_probabilities(c, none, 3, mu));
  CHECK(mu[1] == 0.25);
}

TEST_CASE("log likelihood and NIS of an innovation") {
  CHECK(log_likelihood(3, 2.0, 36.0) == Approx(-0.5 * (2.0 + std::log(36.0) + 3.0 * std::log(2.0 * std::numbers::pi))));
  CHECK(log_likelihood(3, 2.0, 0.0) == -std::numeric_limits<double>::infinity());
  Eigen::Matrix3d S = Eigen::Vector3d(4.0, 9.0, 1.0).asDiagonal();
  S(0, 1) = S(1, 0) = 1.0;
  const Eigen::Vector3d nu(1.0, -2.0, 0.5);
  double nis = 0.0;
  REQUIRE(quadratic_form<3>(S, nu, nis));
  CHECK(nis == Approx(nu.dot(S.inverse() * nu)).epsilon(1e-14));
  S(0, 0) = -1.0;
  CHECK_FALSE(quadratic_form<3>(S, nu, nis));
}
