// Purpose: tests of the fusion math: covariance-intersection weights against a brute-force scan and closed forms, and information matrix fusion against a hand-computed centralised update.
#include "fusion_math.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

using namespace trackflow;
using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;

namespace {

// The CI criterion evaluated directly (inverse of the combination), for a brute-force scan.
double ci_cost(const Mat2& P1, const Mat2& P2, double w, fusion::CiCriterion c) {
  const Mat2 P = (w * P1.inverse() + (1 - w) * P2.inverse()).inverse();
  return c == fusion::CiCriterion::Trace ? P.trace() : P.determinant();
}

double scanned_weight(const Mat2& P1, const Mat2& P2, fusion::CiCriterion c) {
  double best = 1e300, w_best = 0;
  for (int k = 0; k <= 100000; ++k) {
    const double w = k / 100000.0, f = ci_cost(P1, P2, w, c);
    if (f < best) best = f, w_best = w;
  }
  return w_best;
}

}  // namespace

// Mirror-image covariances: w = 1/2 by symmetry for either criterion, and the fused values by
// hand: P = (0.5 diag(1, 1/4) + 0.5 diag(1/4, 1))^-1 = 1.6 I, x = P (0.5 P2^-1 x2) = (0.2, 0.8).
TEST_CASE("track_fusion: CI of mirror-image covariances") {
  const Mat2 P1 = Eigen::Vector2d(1, 4).asDiagonal(), P2 = Eigen::Vector2d(4, 1).asDiagonal();
  for (const auto c : {fusion::CiCriterion::Trace, fusion::CiCriterion::Determinant}) {
    fusion::CiResult<2> r;
    REQUIRE(fusion::covariance_intersection<2>(Vec2(0, 0), P1, Vec2(1, 1), P2, c, r));
    CHECK(r.w == Approx(0.5).margin(1e-8));
    CHECK((r.P - 1.6 * Mat2::Identity()).norm() < 1e-9);
    CHECK(r.x(0) == Approx(0.2).epsilon(1e-9));
    CHECK(r.x(1) == Approx(0.8).epsilon(1e-9));
  }
}

// Correlated, unequal covariances: the weight is the minimiser a direct scan of tr P (det P)
// finds, and the two criteria give different weights.
TEST_CASE("track_fusion: CI weight minimises trace or det") {
  Mat2 P1, P2;
  P1 << 2.0, 0.5, 0.5, 1.0;
  P2 << 1.0, -0.3, -0.3, 3.0;
  fusion::CiResult<2> tr, det;
  REQUIRE(fusion::covariance_intersection<2>(Vec2(1, 2), P1, Vec2(0, 0), P2, fusion::CiCriterion::Trace, tr));
  REQUIRE(fusion::covariance_intersection<2>(Vec2(1, 2), P1, Vec2(0, 0), P2, fusion::CiCriterion::Determinant, det));
  CHECK(tr.w == Approx(scanned_weight(P1, P2, fusion::CiCriterion::Trace)).margin(2e-5));
  CHECK(det.w == Approx(scanned_weight(P1, P2, fusion::CiCriterion::Determinant)).margin(2e-5));
  CHECK(std::abs(tr.w - det.w) > 1e-3);
  // The fused covariance is the combination at that weight.
  const Mat2 P = (tr.w * P1.inverse() + (1 - tr.w) * P2.inverse()).inverse();
  CHECK((tr.P - P).norm() < 1e-9);
  // Consistent for any correlation: P_ci >= the covariance of the fused error for the worst
  // case of fully correlated equal errors is not checked here; CI never claims more than the
  // better input: tr P <= min(tr P1, tr P2).
  CHECK(tr.P.trace() <= std::min(P1.trace(), P2.trace()) + 1e-12);
}

// One estimate far better in every direction: the optimum is the end w = 1, P = P1.
TEST_CASE("track_fusion: CI keeps a dominating estimate") {
  const Mat2 P1 = 0.01 * Mat2::Identity(), P2 = Mat2::Identity();
  fusion::CiResult<2> r;
  REQUIRE(fusion::covariance_intersection<2>(Vec2(1, 1), P1, Vec2(5, 5), P2, fusion::CiCriterion::Trace, r));
  CHECK(r.w == 1.0);
  CHECK((r.P - P1).norm() < 1e-12);
  CHECK((r.x - Vec2(1, 1)).norm() < 1e-12);
}

// Two sensors with a common prior x0 = 0, P0 = 4 (scalar state). Sensor 1: z1 = 1, R1 = 1 gives
// P1 = 1/(1/4 + 1) = 0.8, x1 = 0.8. Sensor 2: z2 = 3, R2 = 4 gives P2 = 2, x2 = 1.5. The
// centralised update: Y = 1/4 + 1 + 1/4 = 1.5, y = 1 + 3/4 = 1.75, x = 7/6, P = 2/3. Information
// matrix fusion reaches it exactly; adding the two posteriors naively (the prior twice) would
// give Y = 1.75.
TEST_CASE("track_fusion: IMF equals the centralised update") {
  using V1 = Eigen::Matrix<double, 1, 1>;
  const V1 x0 = V1::Zero(), P0 = V1::Constant(4.0);
  V1 xf = x0, Pf = P0;
  REQUIRE(fusion::information_fusion<1>(xf, Pf, true, V1::Constant(0.8), V1::Constant(0.8), true, x0, P0));
  CHECK(xf(0) == Approx(0.8).epsilon(1e-12));
  CHECK(Pf(0) == Approx(0.8).epsilon(1e-12));
  REQUIRE(fusion::information_fusion<1>(xf, Pf, true, V1::Constant(1.5), V1::Constant(2.0), true, x0, P0));
  CHECK(xf(0) == Approx(7.0 / 6.0).epsilon(1e-12));
  CHECK(Pf(0) == Approx(2.0 / 3.0).epsilon(1e-12));
  // No fused prior and a local track's first estimate: its information alone.
  V1 xs = V1::Zero(), Ps = V1::Zero();
  REQUIRE(fusion::information_fusion<1>(xs, Ps, false, V1::Constant(1.5), V1::Constant(2.0), false, x0, P0));
  CHECK(xs(0) == Approx(1.5).epsilon(1e-12));
  CHECK(Ps(0) == Approx(2.0).epsilon(1e-12));
}

// A 2-state case with cross-covariances, against the centralised filter computed directly:
// prior x0, P0; sensor 1 sees the first component, sensor 2 the sum.
TEST_CASE("track_fusion: IMF of a correlated 2-state case") {
  Mat2 P0;
  P0 << 3.0, 1.0, 1.0, 2.0;
  const Vec2 x0(0.5, -1.0);
  const Eigen::RowVector2d H1(1, 0), H2(1, 1);
  const double R1 = 0.5, R2 = 2.0, z1 = 1.2, z2 = -0.4;
  auto update = [](const Vec2& x, const Mat2& P, const Eigen::RowVector2d& H, double R, double z, Vec2& xo, Mat2& Po) {
    const double S = (H * P * H.transpose())(0) + R;
    const Vec2 K = P * H.transpose() / S;
    xo = x + K * (z - (H * x)(0));
    Po = (Mat2::Identity() - K * H) * P;
  };
  Vec2 x1, x2, xc, xt;
  Mat2 P1, P2, Pc, Pt;
  update(x0, P0, H1, R1, z1, x1, P1);
  update(x0, P0, H2, R2, z2, x2, P2);
  update(x0, P0, H1, R1, z1, xt, Pt);
  update(xt, Pt, H2, R2, z2, xc, Pc);
  Vec2 xf = x0;
  Mat2 Pf = P0;
  REQUIRE(fusion::information_fusion<2>(xf, Pf, true, x1, P1, true, x0, P0));
  REQUIRE(fusion::information_fusion<2>(xf, Pf, true, x2, P2, true, x0, P0));
  CHECK((xf - xc).norm() < 1e-12);
  CHECK((Pf - Pc).norm() < 1e-12);
}
