// Purpose: tests of angle wrapping, spherical geometry, motion models and the Joseph update.
#include <trackflow/geometry.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>

#include <Eigen/Dense>

#include <catch2/catch.hpp>

#include <numbers>

using namespace trackflow;
constexpr double pi = std::numbers::pi;

TEST_CASE("wrap_angle maps to -pi exclusive to pi inclusive") {
  CHECK(wrap_angle(pi) == Approx(pi));
  CHECK(wrap_angle(-pi) == Approx(pi));
  CHECK(wrap_angle(3 * pi / 2) == Approx(-pi / 2));
  CHECK(wrap_angle(-3 * pi / 2) == Approx(pi / 2));
  CHECK(wrap_angle(0.1 + 20 * pi) == Approx(0.1));
  CHECK(wrap_angle(pi - 1e-12) - (-pi + 1e-12) > 0);  // no jump inside the range
}

TEST_CASE("spherical round trip: both conventions and zenith") {
  for (auto c : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const Vec3 s(12e3, -2.9, 0.3);
    const Vec3 back = enu_to_spherical(spherical_to_enu(s(0), s(1), s(2), c), c);
    CHECK(back(0) == Approx(s(0)));
    CHECK(back(1) == Approx(s(1)));
    CHECK(back(2) == Approx(s(2)));
  }
  const Vec3 z = enu_to_spherical(Vec3(0, 0, 1000), AzimuthConvention::NorthClockwise);
  CHECK(z(0) == Approx(1000));
  CHECK(z(2) == Approx(pi / 2));
  CHECK(std::isfinite(z(1)));
  const Vec3 o = enu_to_spherical(Vec3::Zero(), AzimuthConvention::NorthClockwise);
  CHECK(o.allFinite());
}

// continuous-noise Q of CA is the white-jerk matrix of paper 000 eq 3.19
TEST_CASE("CA continuous-noise Q is paper 000 eq 3.19") {
  const double T = 0.025, q = 2.0;
  const auto Q = ConstantAcceleration::axis_noise_continuous(T, q);
  CHECK(Q(0, 0) == Approx(q * std::pow(T, 5) / 20));
  CHECK(Q(0, 1) == Approx(q * std::pow(T, 4) / 8));
  CHECK(Q(0, 2) == Approx(q * std::pow(T, 3) / 6));
  CHECK(Q(1, 1) == Approx(q * std::pow(T, 3) / 3));
  CHECK(Q(2, 2) == Approx(q * T));
  CHECK((Q - Q.transpose()).norm() == 0.0);
  const auto Qv = ConstantVelocity::axis_noise_continuous(T, q);
  CHECK(Qv(0, 0) == Approx(q * T * T * T / 3));
  CHECK(Qv(0, 1) == Approx(q * T * T / 2));
}

TEST_CASE("propagate equals F x") {
  ConstantAcceleration::State x;
  x << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  ConstantAcceleration::Matrix F;
  ConstantAcceleration::transition(0.5, F);
  const ConstantAcceleration::State expected = F * x;
  ConstantAcceleration::propagate(0.5, x);
  CHECK((x - expected).norm() < 1e-12);
}

// Joseph update keeps P symmetric positive definite and matches the textbook gain
TEST_CASE("Joseph update keeps P symmetric PD with textbook gain") {
  using M = ConstantVelocity;
  M::State x = M::State::Zero();
  M::Matrix P = M::Matrix::Identity() * 100.0;
  P(0, 1) = P(1, 0) = 5.0;
  Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
  for (int a = 0; a < 3; ++a) H(a, M::position_index(a)) = 1.0;
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() * 4.0;
  Eigen::Vector3d nu(1, 2, 3);
  Eigen::Matrix3d S;
  double nis = 0;
  const M::Matrix P0 = P;
  REQUIRE(joseph_update<6, 3>(x, P, nu, H, R, S, nis));
  const Eigen::Matrix<double, 6, 3> K = P0 * H.transpose() * (H * P0 * H.transpose() + R).inverse();
  CHECK((x - K * nu).norm() < 1e-10);
  CHECK((P - (M::Matrix::Identity() - K * H) * P0).norm() < 1e-9);
  CHECK((P - P.transpose()).norm() == 0.0);
  CHECK(Eigen::LLT<M::Matrix>(P).info() == Eigen::Success);
  CHECK(nis == Approx(nu.dot(S.inverse() * nu)));
}

// The update from P H' and S equals the dense Joseph form (for a sparse and a dense H)
TEST_CASE("Joseph update from P H' and S equals the dense form") {
  auto check = [](const Eigen::Matrix<double, 4, 9>& H) {
    Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Random();
    const Eigen::Matrix<double, 9, 9> P0 = A * A.transpose() + 0.1 * Eigen::Matrix<double, 9, 9>::Identity();
    Eigen::Matrix4d B = Eigen::Matrix4d::Random();
    const Eigen::Matrix4d R = B * B.transpose() + 0.5 * Eigen::Matrix4d::Identity();
    const Eigen::Vector4d nu(0.3, -1.2, 0.7, 2.0);
    Eigen::Matrix<double, 9, 1> x_dense = Eigen::Matrix<double, 9, 1>::LinSpaced(1.0, 9.0), x = x_dense;
    Eigen::Matrix<double, 9, 9> P_dense = P0, P = P0;
    Eigen::Matrix4d S_dense, S;
    double nis_dense = 0, nis = 0;
    REQUIRE(joseph_update<9, 4>(x_dense, P_dense, nu, H, R, S_dense, nis_dense));
    const Eigen::Matrix<double, 9, 4> PHt = P0 * H.transpose();
    S = H * PHt + R;
    Eigen::Matrix<double, 9, 4> K;
    double det = 0;
    const double det_expected = S.determinant();
    REQUIRE(joseph_update_cross<9, 4>(x, P, nu, PHt, S, nis, &K, &det));
    CHECK(det == Approx(det_expected).epsilon(1e-12));  // filter.imm's likelihood uses it
    CHECK((x - x_dense).norm() < 1e-12 * x_dense.norm());
    CHECK((P - P_dense).norm() < 1e-12 * P_dense.norm());
    CHECK((S - S_dense).norm() < 1e-12 * S_dense.norm());
    CHECK(nis == Approx(nis_dense).epsilon(1e-12));
    CHECK((K - PHt * S.inverse()).norm() < 1e-10 * K.norm());
    CHECK((P - P.transpose()).norm() == 0.0);
    CHECK(Eigen::LLT<Eigen::Matrix<double, 9, 9>>(P).info() == Eigen::Success);
  };
  Eigen::Matrix<double, 4, 9> sparse = Eigen::Matrix<double, 4, 9>::Zero();
  sparse(0, 0) = 0.6, sparse(0, 3) = 0.8, sparse(1, 0) = -0.2, sparse(1, 3) = 0.3, sparse(2, 6) = 1.0;
  sparse(3, 0) = 0.1, sparse(3, 1) = 0.6, sparse(3, 4) = 0.8;
  check(sparse);
  check(Eigen::Matrix<double, 4, 9>::Random());
}

// An innovation covariance that is not positive definite leaves x and P untouched
TEST_CASE("Joseph update from P H' refuses an indefinite S") {
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Ones();
  Eigen::Matrix<double, 6, 6> P = Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Matrix<double, 6, 6> P0 = P;
  Eigen::Matrix<double, 6, 3> PHt = Eigen::Matrix<double, 6, 3>::Zero();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(1, 1) = -1.0;
  double nis = 0;
  CHECK_FALSE(joseph_update_cross<6, 3>(x, P, Eigen::Vector3d(1, 1, 1), PHt, S, nis));
  S(1, 1) = std::nan("");
  CHECK_FALSE(joseph_update_cross<6, 3>(x, P, Eigen::Vector3d(1, 1, 1), PHt, S, nis));
  CHECK(x == Eigen::Matrix<double, 6, 1>::Ones());
  CHECK(P == P0);
}

TEST_CASE("structured covariance propagation equals F P F'") {
  auto check = [](auto model) {
    using M = decltype(model);
    typename M::Matrix A = M::Matrix::Random();
    typename M::Matrix P = A * A.transpose();
    typename M::Matrix F;
    M::transition(0.7, F);
    const typename M::Matrix expected = F * P * F.transpose();
    M::propagate_covariance(0.7, P);
    CHECK((P - expected).norm() < 1e-12 * expected.norm());
  };
  check(ConstantVelocity{});
  check(ConstantAcceleration{});
}
