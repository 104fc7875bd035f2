// Purpose: tests of the unscented transform header: weights, exactness for linear maps, agreement with the textbook sums, accuracy against Monte Carlo, the azimuth cut, the guarded Cholesky.
#include "unscented_transform.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace trackflow;

namespace {

using Vec6d = Eigen::Matrix<double, 6, 1>;
using Mat6d = Eigen::Matrix<double, 6, 6>;

// h on a CV-layout state [x vx y vy z vz] with the sensor at the origin.
template <int M>
Eigen::Matrix<double, M, 1> h_cv(const Vec6d& s, AzimuthConvention c = AzimuthConvention::NorthClockwise) {
  return spherical_measurement<M>(Vec3(s(0), s(2), s(4)), Vec3(s(1), s(3), s(5)), c);
}

Mat6d random_covariance(Rng& rng, const Vec6d& sigmas) {
  Mat6d A;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = rng.normal();
  Mat6d C = A * A.transpose() / 6.0 + 0.2 * Mat6d::Identity();
  const Vec6d d = C.diagonal().cwiseSqrt().cwiseInverse().cwiseProduct(sigmas);
  C = d.asDiagonal() * C * d.asDiagonal();
  return 0.5 * (C + C.transpose());
}

Eigen::Matrix<double, 6, 6> cholesky(const Mat6d& P) { return P.llt().matrixL(); }

// Moments of h(x), x ~ N(mean, P), by sampling; the azimuth is unwrapped around `az_ref`.
template <int M>
struct SampleMoments {
  Eigen::Matrix<double, M, 1> mean;
  Eigen::Matrix<double, M, M> cov;
  int n = 0;
};
template <int M>
SampleMoments<M> sample_moments(const Vec6d& mean, const Mat6d& P, int n, double az_ref, std::uint64_t seed,
                                AzimuthConvention c = AzimuthConvention::NorthClockwise) {
  const Mat6d L = cholesky(P);
  Rng rng(seed);
  std::vector<Eigen::Matrix<double, M, 1>> z(n);
  SampleMoments<M> out;
  out.n = n;
  out.mean.setZero();
  for (auto& zi : z) {
    Vec6d w;
    for (int i = 0; i < 6; ++i) w(i) = rng.normal();
    zi = h_cv<M>(mean + L * w, c);
    zi(1) = az_ref + std::remainder(zi(1) - az_ref, 2 * std::numbers::pi);
    out.mean += zi / n;
  }
  out.cov.setZero();
  for (const auto& zi : z) out.cov += (zi - out.mean) * (zi - out.mean).transpose() / (n - 1.0);
  return out;
}

}  // namespace

// scaled weights: mean weights sum to one, the defaults put the points at sqrt(3) sigma with W0c >= 0
TEST_CASE("scaled weights sum to one with default spread") {
  for (int n : {6, 9})
    for (double alpha : {1e-3, 0.5, 1.0})
      for (double kappa : {0.0, 3.0 - n, 1.0}) {
        const auto w = ukf::ScaledWeights::make(n, alpha, 2.0, kappa);
        CHECK(w.mean0 + 2 * n * w.other == Approx(1.0));
        CHECK(w.spread * w.spread == Approx(alpha * alpha * (n + kappa)));
      }
  for (int n : {6, 9}) {
    const auto w = ukf::ScaledWeights::make(n, 1.0, 2.0, 3.0 - n);
    CHECK(w.spread == Approx(std::sqrt(3.0)));
    CHECK(w.cov0 >= 0.0);
    CHECK(w.mean0 == Approx((3.0 - n) / 3.0));
  }
  // Wan & van der Merwe's alpha = 1e-3: a huge negative centre weight.
  CHECK(ukf::ScaledWeights::make(6, 1e-3, 2.0, 0.0).cov0 < -1e5);
}

// for a linear map the transform is exact: mean A x + b, H = A, nothing left over
TEST_CASE("the transform is exact for a linear map") {
  Rng rng(4);
  Eigen::Matrix<double, 3, 6> A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = 0.01 * rng.normal();
  const Eigen::Vector3d b(100, 0.2, -0.3);
  Vec6d x;
  x << 1, 2, 3, 4, 5, 6;
  const Mat6d P = random_covariance(rng, (Vec6d() << 5, 1, 5, 1, 5, 1).finished());
  const Mat6d L = cholesky(P);
  auto h = [&](const Vec6d& s) { return Eigen::Vector3d(A * s + b); };
  for (double alpha : {0.3, 1.0})
    for (double kappa : {0.0, -3.0, 2.0}) {
      ukf::MeasurementMoments<6, 3> ut;
      ukf::unscented_measurement<6, 3>(x, L, ukf::ScaledWeights::make(6, alpha, 2.0, kappa), h, ut);
      CHECK((ut.mean - (A * x + b)).norm() < 1e-12);
      CHECK((ut.H - A).norm() < 1e-12 * A.norm());
      CHECK(ut.extra.norm() < 1e-20);
    }
}

// H P H' + extra and P H' are the textbook unscented P_zz and P_xz
TEST_CASE("H P H' + extra and P H' are textbook P_zz P_xz") {
  Rng rng(8);
  Vec6d x;
  x << 900, -40, 700, 25, 300, 5;  // about 1.2 km from the sensor
  const Mat6d P = random_covariance(rng, (Vec6d() << 150, 20, 120, 20, 80, 5).finished());
  const Mat6d L = cholesky(P);
  for (double kappa : {-3.0, 0.0, 1.0}) {
    const auto w = ukf::ScaledWeights::make(6, 1.0, 2.0, kappa);
    ukf::MeasurementMoments<6, 4> ut;
    ukf::unscented_measurement<6, 4>(x, L, w, [](const Vec6d& s) { return h_cv<4>(s); }, ut);
    // Textbook sums over the 2n + 1 points (no point near the azimuth cut here).
    const double c = std::sqrt(6 + w.lambda);
    std::vector<Vec6d> X{x};
    for (int j = 0; j < 6; ++j) {
      X.push_back(x + c * L.col(j));
      X.push_back(x - c * L.col(j));
    }
    Eigen::Vector4d zbar = Eigen::Vector4d::Zero();
    for (size_t i = 0; i < X.size(); ++i) zbar += (i == 0 ? w.mean0 : w.other) * h_cv<4>(X[i]);
    Eigen::Matrix4d Pzz = Eigen::Matrix4d::Zero();
    Eigen::Matrix<double, 6, 4> Pxz = Eigen::Matrix<double, 6, 4>::Zero();
    for (size_t i = 0; i < X.size(); ++i) {
      const double wc = i == 0 ? w.cov0 : w.other;
      const Eigen::Vector4d dz = h_cv<4>(X[i]) - zbar;
      Pzz += wc * dz * dz.transpose();
      Pxz += wc * (X[i] - x) * dz.transpose();
    }
    INFO("kappa " << kappa);
    CHECK((ut.mean - zbar).norm() < 1e-9 * zbar.norm());
    CHECK((ut.H * P * ut.H.transpose() + ut.extra - Pzz).norm() < 1e-9 * Pzz.norm());
    CHECK((P * ut.H.transpose() - Pxz).norm() < 1e-9 * Pxz.norm());
  }
}

// as P shrinks the statistical linearisation tends to the analytic Jacobian
TEST_CASE("small P: statistical H tends to the Jacobian") {
  Vec6d x;
  x << 4e3, -100, 3e3, 50, 1e3, 10;
  Rng rng(2);
  const Mat6d P0 = random_covariance(rng, (Vec6d() << 1, 1, 1, 1, 1, 1).finished());
  SphericalJacobian<4> J;
  const auto c = AzimuthConvention::NorthClockwise;
  spherical_measurement_jacobian<4>(Vec3(x(0), x(2), x(4)), Vec3(x(1), x(3), x(5)), c, J);
  Eigen::Matrix<double, 4, 6> Hj;  // columns scattered into the CV layout
  for (int a = 0; a < 3; ++a) {
    Hj.col(2 * a) = J.col(a);
    Hj.col(2 * a + 1) = J.col(a + 3);
  }
  // Central differences along the sigma directions: the error falls like (c sigma / r)^2 until
  // rounding (~1e-16 r / (c sigma)) takes over, below the scales used here.
  double prev = 1e300;
  for (double s : {30.0, 3.0, 0.3}) {
    ukf::MeasurementMoments<6, 4> ut;
    ukf::unscented_measurement<6, 4>(x, cholesky(s * s * P0), ukf::ScaledWeights::make(6, 1.0, 2.0, -3.0),
                                     [](const Vec6d& v) { return h_cv<4>(v); }, ut);
    const double err = (ut.H - Hj).norm() / Hj.norm();
    INFO("scale " << s << " relative difference " << err);
    CHECK(err < prev);
    prev = err;
  }
  CHECK(prev < 1e-7);
}

// strongly nonlinear (300 m range, 100 m position sigma): the UT mean matches Monte Carlo, h(mean) does not
TEST_CASE("strongly nonlinear: UT mean matches Monte Carlo") {
  Vec6d x;
  x << 200, 10, 200, -5, 100, 0;  // 300 m from the sensor
  const Mat6d P = (Vec6d() << 1e4, 1, 1e4, 1, 1e4, 1).finished().asDiagonal();
  const int n = 400000;
  const auto mc = sample_moments<3>(x, P, n, std::atan2(x(0), x(2)), 99);
  const Eigen::Vector3d lin = h_cv<3>(x);
  for (double kappa : {-3.0, 0.0}) {
    ukf::MeasurementMoments<6, 3> ut;
    ukf::unscented_measurement<6, 3>(x, cholesky(P), ukf::ScaledWeights::make(6, 1.0, 2.0, kappa),
                                     [](const Vec6d& v) { return h_cv<3>(v); }, ut);
    const Eigen::Matrix3d Pzz = ut.H * P * ut.H.transpose() + ut.extra;
    for (int i = 0; i < 3; ++i) {
      const double se = std::sqrt(mc.cov(i, i) / n);  // standard error of the sample mean
      INFO("kappa " << kappa << " element " << i << ": MC " << mc.mean(i) << " +- " << se << ", UT " << ut.mean(i)
                    << ", h(mean) " << lin(i) << "; var MC " << mc.cov(i, i) << " UT " << Pzz(i, i));
      CHECK(std::abs(ut.mean(i) - mc.mean(i)) <= std::abs(lin(i) - mc.mean(i)) + 4 * se);
    }
    // Range: E[r] exceeds |mean| by about sigma^2/r (~33 m); the UT captures most of it.
    CHECK(lin(0) < mc.mean(0) - 20.0);
    CHECK(std::abs(ut.mean(0) - mc.mean(0)) < 0.35 * std::abs(lin(0) - mc.mean(0)));
  }
}

// sigma points straddling the azimuth cut: mean at +-pi, covariance as on any other bearing
TEST_CASE("sigma points across the azimuth cut") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const bool nc = c == AzimuthConvention::NorthClockwise;
    Vec6d x = Vec6d::Zero();  // due south (north_clockwise) or due west (x_counterclockwise), 2 km
    (nc ? x(2) : x(0)) = -2000;
    x(4) = 300;
    const Mat6d P = (Vec6d() << 60 * 60, 1, 60 * 60, 1, 30 * 30, 1).finished().asDiagonal();
    // Points at sqrt(3) x 60 m across a 2 km line of sight: az = pi +- 0.05 rad.
    auto h = [c](const Vec6d& s) { return h_cv<3>(s, c); };
    ukf::MeasurementMoments<6, 3> ut;
    ukf::unscented_measurement<6, 3>(x, cholesky(P), ukf::ScaledWeights::make(6, 1.0, 2.0, -3.0), h, ut);
    const double cross = 60.0 / 2000.0;  // cross-range sigma over range, rad
    const Eigen::Matrix3d Pzz = ut.H * P * ut.H.transpose() + ut.extra;
    INFO("convention " << int(c) << ": mean az " << ut.mean(1) << ", var az " << Pzz(1, 1));
    CHECK(std::abs(wrap_angle(ut.mean(1) - std::numbers::pi)) < 1e-12);
    CHECK(ut.mean(1) > -std::numbers::pi);
    CHECK(ut.mean(1) <= std::numbers::pi);
    CHECK(Pzz(1, 1) == Approx(cross * cross).epsilon(0.01));
    // The same target rotated away from the cut gives the same moments.
    Vec6d xr = x;
    (nc ? xr(2) : xr(0)) = 0;
    (nc ? xr(0) : xr(2)) = -2000;  // due west / due south: az = -pi/2
    ukf::MeasurementMoments<6, 3> ref;
    ukf::unscented_measurement<6, 3>(xr, cholesky(P), ukf::ScaledWeights::make(6, 1.0, 2.0, -3.0), h, ref);
    const Eigen::Matrix3d Pref = ref.H * P * ref.H.transpose() + ref.extra;
    CHECK((Pzz - Pref).norm() < 1e-12 * Pref.norm());
    CHECK(std::abs(ut.mean(0) - ref.mean(0)) < 1e-9);
    // And the sampled moments (azimuth unwrapped around pi) agree.
    const int n = 200000;
    const auto mc = sample_moments<3>(x, P, n, std::numbers::pi, 7, c);
    CHECK(std::abs(wrap_angle(ut.mean(1) - mc.mean(1))) < 4 * std::sqrt(mc.cov(1, 1) / n));
    CHECK(Pzz(1, 1) == Approx(mc.cov(1, 1)).epsilon(4 * std::sqrt(2.0 / n)));
  }
}

// guarded Cholesky: untouched when positive definite, jitter for a singular P, refusal when indefinite
TEST_CASE("guarded Cholesky: PD singular and indefinite P") {
  Rng rng(12);
  Mat6d P = random_covariance(rng, (Vec6d() << 10, 1, 10, 1, 10, 1).finished());
  const Mat6d P0 = P;
  Mat6d L;
  CHECK(ukf::guarded_cholesky<6>(P, L) == 0.0);
  CHECK(P == P0);
  CHECK((L * L.transpose() - P).norm() < 1e-12 * P.norm());
  CHECK((L - Mat6d(P.llt().matrixL())).norm() < 1e-12 * L.norm());

  // Indefinite at the rounding level (smallest eigenvalue -1e-9 of the largest variance), as
  // P - K S K' can become, and slightly asymmetric.
  Mat6d S = random_covariance(rng, (Vec6d() << 10, 1, 10, 1, 10, 1).finished());
  const double scale = S.diagonal().maxCoeff();
  S.diagonal().array() -= Eigen::SelfAdjointEigenSolver<Mat6d>(S).eigenvalues()(0) + 1e-9 * scale;
  S(0, 1) += 1e-14 * scale;
  const Mat6d S0 = S;
  REQUIRE(S.llt().info() != Eigen::Success);
  const double jitter = ukf::guarded_cholesky<6>(S, L);
  CHECK(jitter > 1e-9 * scale);
  CHECK(jitter <= 1e-7 * scale);
  CHECK(S.isApprox(S.transpose(), 0.0));
  CHECK(L.allFinite());
  CHECK((L * L.transpose() - S).norm() < 1e-12 * S.norm());
  CHECK((S - S0).norm() < 1e-3 * S0.norm());

  Mat6d I = Mat6d::Identity();
  I(3, 3) = -0.5;
  CHECK(ukf::guarded_cholesky<6>(I, L) < 0.0);
  Mat6d nan = Mat6d::Identity();
  nan(2, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK(ukf::guarded_cholesky<6>(nan, L) < 0.0);
  Mat6d zero = Mat6d::Zero();
  CHECK(ukf::guarded_cholesky<6>(zero, L) < 0.0);
}
