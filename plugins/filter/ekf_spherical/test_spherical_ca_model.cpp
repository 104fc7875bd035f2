// Purpose: tests of the spherical CA model against independent numerics: F vs central differences, truncation order against exact Cartesian motion, the ENU map, two-point init.
#include "spherical_ca_model.hpp"
#include "spherical_two_point.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

using namespace trackflow;
using namespace trackflow::ekf_spherical;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

State make_state(double R, double vr, double ar, double th, double vh, double ah, double ph, double vv, double av) {
  State x;
  x << R, vr, ar, th, vh, ah, ph, vv, av;
  return x;
}

// Step per state for central differences: relative to the value, with a floor per kind.
double step_for(int i, const State& x) {
  switch (i) {
    case kR: return 1e-6 * std::abs(x(kR));
    case kTheta:
    case kPhi: return 1e-7;
    default: return 1e-6 * std::max(1.0, std::abs(x(i)));
  }
}

Matrix numerical_jacobian(const State& x, double T, const Guard& g) {
  Matrix F;
  for (int j = 0; j < kDim; ++j) {
    const double h = step_for(j, x);
    State xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    propagate(xp, T, g);
    propagate(xm, T, g);
    F.col(j) = (xp - xm) / (2 * h);
  }
  return F;
}

// Entry-wise comparison after scaling rows and columns by the states' natural sizes, so that
// entries of very different units (1e-9 rad/m next to 1) are compared on one footing.
void check_close(const Matrix& A, const Matrix& B, const State& scale, double tol) {
  Matrix As = A, Bs = B;
  for (int i = 0; i < kDim; ++i)
    for (int j = 0; j < kDim; ++j) {
      As(i, j) *= scale(j) / scale(i);
      Bs(i, j) *= scale(j) / scale(i);
    }
  const double ref = std::max(As.cwiseAbs().maxCoeff(), 1e-300);
  for (int i = 0; i < kDim; ++i)
    for (int j = 0; j < kDim; ++j) {
      INFO("entry (" << i << ", " << j << "): analytic " << A(i, j) << ", numerical " << B(i, j));
      CHECK(std::abs(As(i, j) - Bs(i, j)) <= tol * (ref + std::abs(As(i, j))));
    }
}

State natural_scale(const State& x) {
  State s;
  s << x(kR), 100, 1, 1, 100, 1, 1, 100, 1;
  return s;
}

// Five-point central derivative of a scalar function of time.
double derivative(const std::function<double(double)>& f, double t, double h) {
  return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h);
}

// The exact spherical state of a target at d(t) relative to the sensor, from finite differences
// of its exact spherical coordinates (azimuth unwrapped locally around t).
State exact_state(const std::function<Vec3(double)>& d, double t, AzimuthConvention c) {
  const double th0 = enu_to_spherical(d(t), c)(1);
  auto R = [&](double s) { return enu_to_spherical(d(s), c)(0); };
  auto th = [&](double s) { return th0 + wrap_angle(enu_to_spherical(d(s), c)(1) - th0); };
  auto ph = [&](double s) { return enu_to_spherical(d(s), c)(2); };
  const double h = 1e-2;
  auto vr = [&](double s) { return derivative(R, s, h); };
  auto vh = [&](double s) { return R(s) * std::cos(ph(s)) * derivative(th, s, h); };
  auto vv = [&](double s) { return R(s) * derivative(ph, s, h); };
  const double H = 5e-2;
  return make_state(R(t), vr(t), derivative(vr, t, H), th(t), vh(t), derivative(vh, t, H), ph(t), vv(t),
                    derivative(vv, t, H));
}

}  // namespace

// analytic F equals a central-difference Jacobian of f, including large T and high elevation
TEST_CASE("analytic F equals a numerical Jacobian of f") {
  const Guard g;
  struct Case {
    State x;
    double T;
  };
  const std::vector<Case> cases = {
      {make_state(50e3, -200, 1.5, 0.7, 250, -2, 0.2, 30, 0.5), 0.025},
      {make_state(50e3, -200, 1.5, 0.7, 250, -2, 0.2, 30, 0.5), 5.0},
      {make_state(8e3, 300, -3, -2.9, -150, 4, 0.5, -80, 2), 20.0},
      {make_state(20e3, 50, 0.2, 3.1, 400, -1, 80 * kDeg, 120, -0.5), 1.0},
      {make_state(20e3, 50, 0.2, 3.1, 400, -1, 87.5 * kDeg, 120, -0.5), 1.0},
      {make_state(15e3, -50, 0.0, 1.0, -300, 2, -70 * kDeg, -200, 1), 2.0},
      {make_state(600, 10, 5, -0.3, 40, -6, 0.1, 3, -1), 0.5},
  };
  for (const auto& c : cases) {
    INFO("state " << c.x.transpose() << ", T " << c.T);
    Matrix F;
    jacobian(c.x, c.T, g, F);
    check_close(F, numerical_jacobian(c.x, c.T, g), natural_scale(c.x), 1e-6);
  }
}

TEST_CASE("inside the guard F is the guarded f Jacobian") {
  Guard g;
  g.min_range = 1.0;
  g.max_elevation = 85 * kDeg;
  for (const State& x : {make_state(5e3, 20, 1, 0.4, 100, 1, 88 * kDeg, 50, 1),   // above the elevation limit
                         make_state(0.5, 20, 1, 0.4, 100, 1, 0.3, 50, 1),          // inside min_range
                         make_state(0.5, 20, 1, 0.4, 100, 1, -89 * kDeg, 50, 1)}) {
    Matrix F;
    jacobian(x, 0.1, g, F);
    CHECK(F.allFinite());
    check_close(F, numerical_jacobian(x, 0.1, g), natural_scale(x), 1e-6);
  }
}

// the entries paper 000 prints wrongly in eq 3.60 differ from the numerical Jacobian; ours agree
TEST_CASE("paper 000 eq 3.60 misprints are corrected") {
  const Guard g;
  const State x = make_state(30e3, -150, 2, 0.5, 220, -3, 0.6, 90, 1.5);
  const double T = 2.0, R = x(kR), vr = x(kVr), ar = x(kAr), vh = x(kVh), ah = x(kAh), ph = x(kPhi), vv = x(kVv),
               av = x(kAv);
  const double Rh = R * std::cos(ph), t = std::tan(ph), sec2 = 1 / (std::cos(ph) * std::cos(ph));
  const Matrix N = numerical_jacobian(x, T, g);
  auto rel = [](double a, double b) { return std::abs(a - b) / std::max(std::abs(a), std::abs(b)); };
  // F41 as printed: last term with v̇_r instead of v̇_h.
  const double F41_printed = -(T * vh / (R * Rh)) * (1 + (T / R) * (vv * t - vr)) - T * T * ar / (2 * R * Rh);
  CHECK(rel(F41_printed, N(kTheta, kR)) > 1e-3);
  // F43 = T²/(2 R_h) is printed in the v̇_r column; θ does not depend on v̇_r, it is ∂θ/∂v̇_h.
  CHECK(std::abs(N(kTheta, kAr)) < 1e-12);
  CHECK(N(kTheta, kAh) == Approx(T * T / (2 * Rh)).epsilon(1e-6));
  // F47 as printed: T v̇_r / 2 inside the bracket instead of T v̇_h / 2.
  const double F47_printed = T * T * vh * vv * sec2 / (2 * R * Rh) +
                             (T * t / Rh) * (vh + T * ar / 2 + (T * vh / (2 * R)) * (vv * t - vr));
  CHECK(rel(F47_printed, N(kTheta, kPhi)) > 1e-3);
  // F71 as printed: [1 + T v_r / R] instead of [1 − T v_r / R].
  const double F71_printed = -(T * vv / (R * R)) * (1 + T * vr / R) - T * T * av / (2 * R * R);
  CHECK(rel(F71_printed, N(kPhi, kR)) > 1e-3);
  Matrix F;
  jacobian(x, T, g, F);
  for (auto [i, j] : {std::pair{kTheta, kR}, {kTheta, kAh}, {kTheta, kPhi}, {kPhi, kR}})
    CHECK(F(i, j) == Approx(N(i, j)).epsilon(1e-6));
  // The entries the paper prints correctly match too (F42, F45, F48, F72, F78, F79).
  CHECK(F(kTheta, kVr) == Approx(-T * T * vh / (2 * R * Rh)).epsilon(1e-12));
  CHECK(F(kTheta, kVh) == Approx((T / Rh) * (1 + (T / (2 * R)) * (vv * t - vr))).epsilon(1e-12));
  CHECK(F(kTheta, kVv) == Approx(T * T * vh * t / (2 * R * Rh)).epsilon(1e-12));
  CHECK(F(kPhi, kVr) == Approx(-T * T * vv / (2 * R * R)).epsilon(1e-12));
  CHECK(F(kPhi, kVv) == Approx((T / R) * (1 - T * vr / (2 * R))).epsilon(1e-12));
  CHECK(F(kPhi, kAv) == Approx(T * T / (2 * R)).epsilon(1e-12));
}

// one step of f on a constant-velocity Cartesian target: position error O(T^3), velocity O(T^2)
TEST_CASE("one step of f on a CV target: error orders") {
  const Guard g;
  struct Geometry {
    Vec3 d0, v;
    AzimuthConvention c;
  };
  const std::vector<Geometry> geometries = {
      {Vec3(4e3, 9e3, 2e3), Vec3(-250, 40, 30), AzimuthConvention::NorthClockwise},
      {Vec3(-6e3, 3e3, 8e3), Vec3(120, 200, -90), AzimuthConvention::XCounterClockwise},
      {Vec3(1e3, -2e3, 1.5e4), Vec3(300, 100, 0), AzimuthConvention::NorthClockwise},  // elevation ~80 deg
  };
  for (const auto& geo : geometries) {
    auto d = [&](double s) -> Vec3 { return geo.d0 + geo.v * s; };
    const State x0 = exact_state(d, 0.0, geo.c);
    std::vector<double> pos_err, vel_err;
    for (double T : {4.0, 2.0, 1.0}) {
      State x = x0;
      propagate(x, T, g);
      const State xt = exact_state(d, T, geo.c);
      const double R = xt(kR);
      pos_err.push_back(std::abs(x(kR) - xt(kR)) + R * std::abs(wrap_angle(x(kTheta) - xt(kTheta))) +
                        R * std::abs(x(kPhi) - xt(kPhi)));
      vel_err.push_back(std::abs(x(kVr) - xt(kVr)) + std::abs(x(kVh) - xt(kVh)) + std::abs(x(kVv) - xt(kVv)));
    }
    INFO("d0 " << geo.d0.transpose() << ": position errors " << pos_err[0] << ", " << pos_err[1] << ", "
               << pos_err[2] << " m; velocity errors " << vel_err[0] << ", " << vel_err[1] << ", " << vel_err[2]);
    for (int k = 0; k + 1 < 3; ++k) {
      // Halving T: a third-order error falls by 8, a second-order one by 4 (allowing for the next term).
      CHECK(pos_err[k] / pos_err[k + 1] > 6.0);
      CHECK(pos_err[k] / pos_err[k + 1] < 10.0);
      CHECK(vel_err[k] / vel_err[k + 1] > 3.0);
      CHECK(vel_err[k] / vel_err[k + 1] < 5.0);
    }
    CHECK(pos_err[2] > 1e-6);  // the comparison measured the model, not rounding
  }
}

// ENU map: Jacobian equals central differences; velocity equals the derivative of position
TEST_CASE("ENU map Jacobian and velocity are consistent") {
  for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (const State& x : {make_state(30e3, -150, 2, 0.5, 220, -3, 0.6, 90, 1.5),
                           make_state(900, 20, 0, -2.8, -60, 0, -0.4, 10, 0),
                           make_state(12e3, 0, 0, 3.0, 0, 0, 1.45, -300, 0)}) {
      EnuJacobian J;
      to_enu(x, conv, &J);
      EnuJacobian N;
      for (int j = 0; j < kDim; ++j) {
        const double h = step_for(j, x);
        State xp = x, xm = x;
        xp(j) += h;
        xm(j) -= h;
        N.col(j) = (to_enu(xp, conv) - to_enu(xm, conv)) / (2 * h);
      }
      CHECK((J - N).norm() <= 1e-6 * J.norm());
    }
    // Along an accelerating Cartesian trajectory the spherical rates from finite differences of
    // (R, θ, φ) map to the true velocity, and R e_r to the true position.
    auto d = [](double s) -> Vec3 {
      return Vec3(3e3, -7e3, 2.5e3) + Vec3(-120, 250, 60) * s + 0.5 * Vec3(4, -3, -9.8) * s * s;
    };
    auto vel = [](double s) -> Vec3 { return Vec3(-120, 250, 60) + Vec3(4, -3, -9.8) * s; };
    for (double t : {0.0, 7.0, 15.0}) {
      const State x = exact_state(d, t, conv);
      const Vec6 e = to_enu(x, conv);
      CHECK((e.head<3>() - d(t)).norm() < 1e-8 * d(t).norm());
      CHECK((e.tail<3>() - vel(t)).norm() < 1e-6 * vel(t).norm());
    }
  }
}

// v_h points toward increasing azimuth in both conventions
TEST_CASE("v_h points toward increasing azimuth") {
  // Due north of the sensor, moving east: the compass bearing increases, the math angle decreases.
  const Vec3 d0(0, 10e3, 0), v(100, 0, 0);
  auto d = [&](double s) -> Vec3 { return d0 + v * s; };
  const State cw = exact_state(d, 0.0, AzimuthConvention::NorthClockwise);
  const State ccw = exact_state(d, 0.0, AzimuthConvention::XCounterClockwise);
  CHECK(cw(kVh) == Approx(100).epsilon(1e-6));
  CHECK(ccw(kVh) == Approx(-100).epsilon(1e-6));
  CHECK(to_enu(cw, AzimuthConvention::NorthClockwise).tail<3>().isApprox(v, 1e-6));
  CHECK(to_enu(ccw, AzimuthConvention::XCounterClockwise).tail<3>().isApprox(v, 1e-6));
}

// process noise: paper's Q1 per channel with the angle rows scaled by 1/R_h and 1/R
TEST_CASE("process noise is the paper's scaled Q1") {
  const Guard g;
  const State x = make_state(20e3, 0, 0, 0.3, 0, 0, 0.5, 0, 0);
  const double T = 0.5, q[3] = {2.0, 3.0, 5.0};
  Matrix Q;
  process_noise(x, ConstantAcceleration::axis_noise_continuous(T, 1.0), q, g, Q);
  const double Rh = 20e3 * std::cos(0.5), R = 20e3;
  // Written out from eq 3.58 / 3.19, not from the code's blocks.
  CHECK(Q(kR, kR) == Approx(2.0 * std::pow(T, 5) / 20));
  CHECK(Q(kVr, kAr) == Approx(2.0 * T * T / 2));
  CHECK(Q(kTheta, kTheta) == Approx(3.0 * std::pow(T, 5) / 20 / (Rh * Rh)));
  CHECK(Q(kTheta, kVh) == Approx(3.0 * std::pow(T, 4) / 8 / Rh));
  CHECK(Q(kVh, kVh) == Approx(3.0 * std::pow(T, 3) / 3));
  CHECK(Q(kAh, kAh) == Approx(3.0 * T));
  CHECK(Q(kPhi, kAv) == Approx(5.0 * std::pow(T, 3) / 6 / R));
  CHECK(Q(kVv, kVv) == Approx(5.0 * std::pow(T, 3) / 3));
  CHECK(Q(kR, kTheta) == 0.0);
  CHECK((Q - Q.transpose()).norm() == 0.0);
  CHECK(Eigen::SelfAdjointEigenSolver<Matrix>(Q).eigenvalues().minCoeff() > -1e-18);
}

// two-point initial covariance matches the Monte Carlo spread of the initial state
TEST_CASE("two-point P0 matches the Monte Carlo spread") {
  const double T = 0.5;
  const Vec3 d1(30e3, 40e3, 10e3), v(-200, 150, 40);
  const Vec3 d2 = d1 + v * T;
  for (bool use_rate : {false, true}) {
    for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
      Meas4 z1t, z2t;
      z1t << enu_to_spherical(d1, conv), range_rate(d1, v);
      z2t << enu_to_spherical(d2, conv), range_rate(d2, v);
      Cov4 R = Cov4::Zero();
      R.diagonal() << 25.0, 1e-6, 2e-6, 0.25;
      R(0, 2) = R(2, 0) = 0.5 * std::sqrt(25.0 * 2e-6);  // correlated range/elevation noise
      const Eigen::Matrix4d L = R.llt().matrixL();
      State x;
      Matrix P;
      two_point_state(z1t, R, z2t, R, T, use_rate, 7.0, x, P);
      const int n = 20000;
      Rng rng(11);
      const int idx[6] = {kR, kVr, kTheta, kVh, kPhi, kVv};
      Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
      Eigen::Matrix<double, 6, 6> M2 = Eigen::Matrix<double, 6, 6>::Zero();
      for (int k = 0; k < n; ++k) {
        const Meas4 z1 = z1t + L * Meas4(rng.normal(), rng.normal(), rng.normal(), rng.normal());
        const Meas4 z2 = z2t + L * Meas4(rng.normal(), rng.normal(), rng.normal(), rng.normal());
        State xs;
        Matrix Ps;
        two_point_state(z1, R, z2, R, T, use_rate, 7.0, xs, Ps);
        Eigen::Matrix<double, 6, 1> y;
        for (int i = 0; i < 6; ++i) y(i) = xs(idx[i]) - x(idx[i]);
        y(2) = wrap_angle(y(2));
        mean += y;
        M2 += y * y.transpose();
      }
      mean /= n;
      const Eigen::Matrix<double, 6, 6> C = M2 / n - mean * mean.transpose();
      for (int i = 0; i < 6; ++i) {
        const double Pii = P(idx[i], idx[i]);
        INFO("state " << idx[i] << " use_rate " << use_rate);
        // The sample variance's relative std is sqrt(2/n) = 1 %; 5 sigma.
        CHECK(C(i, i) == Approx(Pii).epsilon(5 * std::sqrt(2.0 / n)));
        CHECK(std::abs(mean(i)) < 5 * std::sqrt(Pii / n));
        for (int j = 0; j < i; ++j) {
          const double Pij = P(idx[i], idx[j]), sij = std::sqrt(Pii * P(idx[j], idx[j]));
          CHECK(std::abs(C(i, j) - Pij) < 5 * sij / std::sqrt(n));
        }
      }
      CHECK(P(kAh, kAh) == 49.0);
      // Positive definite: scale-free check on the correlation matrix.
      const State sd = P.diagonal().cwiseSqrt();
      const Matrix Corr = sd.cwiseInverse().asDiagonal() * P * sd.cwiseInverse().asDiagonal();
      CHECK(Eigen::SelfAdjointEigenSolver<Matrix>(Corr).eigenvalues().minCoeff() > 0.0);
    }
  }
}

// folding a state over the zenith changes its coordinates, not the point, velocity or ENU covariance
TEST_CASE("folding over the zenith keeps the ENU state") {
  Rng rng(21);
  for (double phi : {1.7, 2.5, -1.65, -3.0}) {
    State x = make_state(12e3, -40, 1, 2.9, 130, -2, phi, 75, 0.5);
    Eigen::Matrix<double, kDim, kDim> A;
    for (int i = 0; i < kDim; ++i)
      for (int j = 0; j < kDim; ++j) A(i, j) = rng.normal();
    Matrix P = A * A.transpose() + Matrix::Identity();
    for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
      State y = x;
      Matrix Py = P;
      REQUIRE(fold_over_zenith(y, Py));
      CHECK(std::abs(y(kPhi)) <= kPi / 2);
      CHECK(y(kTheta) > -kPi);
      CHECK(y(kTheta) <= kPi);
      EnuJacobian Jx, Jy;
      const Vec6 ex = to_enu(x, conv, &Jx), ey = to_enu(y, conv, &Jy);
      CHECK((ex - ey).norm() < 1e-9 * ex.norm());
      const Mat6 Cx = Jx * P * Jx.transpose(), Cy = Jy * Py * Jy.transpose();
      CHECK((Cx - Cy).norm() < 1e-9 * Cx.norm());
      // The radial channel and the v̇_r state are untouched.
      CHECK(y(kR) == x(kR));
      CHECK(Py(kR, kVr) == P(kR, kVr));
    }
  }
  State inside = make_state(1e3, 0, 0, 0.3, 0, 0, 1.2, 0, 0);
  Matrix P = Matrix::Identity();
  CHECK_FALSE(fold_over_zenith(inside, P));
}
