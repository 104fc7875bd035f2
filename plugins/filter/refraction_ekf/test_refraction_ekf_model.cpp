// Purpose: tests of the 13-state model: analytic Jacobian (paper 004 eq 10, corrected) against a numerical one, and the radar-state rates against the derivatives of the geometry.
#include "refraction_ekf_model.hpp"

#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace trackflow;
namespace rx = trackflow::refraction_ekf;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// A launch-vehicle-like state: range ~1000 km at `el_deg`, 3 km/s, accelerating, b from Clark.
rx::State sample_state(double el_deg, double az_deg, const rx::Model& m) {
  const double r = 1.2e6, el = el_deg * kDeg, az = az_deg * kDeg;
  const Vec3 p = spherical_to_enu(r, az, el, AzimuthConvention::NorthClockwise);
  const Vec3 v(1200.0, -2500.0, -300.0), vp(1199.0, -2501.5, -300.4);
  rx::State X;
  for (int a = 0; a < 3; ++a) {
    X(rx::pos(a)) = p(a);
    X(rx::vel(a)) = v(a);
    X(rx::prev(a)) = vp(a);
  }
  X(rx::kRange) = r + 3.0;
  X(rx::kAzimuth) = az + 2e-5;
  X(rx::kElevation) = el - 1e-5;
  X(rx::kBias) = m.clark.bias(el);
  return X;
}

}  // namespace

// Every entry of A = df/dX against central differences of f (step relative to each state's
// scale), for both azimuth conventions, both position updates, theta in rad and deg inside beta1,
// below and above 10 deg, with and without the bias state. This is the check paper 004's eq 10
// needs: its printed entries have typos (d rho/dx for d rho-dot/dx, "2zz", a duplicated row, and
// d b-dot / d theta without theta-dot).
TEST_CASE("jacobian matches a numerical jacobian") {
  for (double sign : {-1.0, 1.0})
    for (auto pos : {rx::Position::Euler, rx::Position::AdamsBashforth2})
      for (auto unit : {sim::ClarkThetaUnit::Radian, sim::ClarkThetaUnit::Degree})
        for (bool bias : {true, false})
          for (double el : {2.5, 5.0, 9.5, 15.0, 40.0}) {
            rx::Model m;
            m.azimuth_sign = sign;
            m.position = pos;
            m.clark.unit = unit;
            m.clark.below = sim::ClarkBelow::Hold;
            m.bias = bias;
            const rx::State X = sample_state(el, 150.0, m);
            const double T = 0.025;
            rx::Matrix A;
            rx::propagate(X, T, m, &A);
            rx::Matrix N;
            for (int j = 0; j < rx::kN; ++j) {
              const double h = j < 9 ? (j % 3 == 0 ? 100.0 : 1.0) : (j == rx::kRange ? 10.0 : 1e-6);
              rx::State Xp = X, Xm = X;
              Xp(j) += h;
              Xm(j) -= h;
              N.col(j) = (rx::propagate(Xp, T, m) - rx::propagate(Xm, T, m)) / (2 * h);
            }
            for (int i = 0; i < rx::kN; ++i)
              for (int j = 0; j < rx::kN; ++j) {
                INFO("sign " << sign << " euler " << (pos == rx::Position::Euler) << " deg "
                             << (unit == sim::ClarkThetaUnit::Degree) << " bias " << bias << " el " << el
                             << " entry " << i << "," << j);
                CHECK(A(i, j) == Approx(N(i, j)).margin(1e-12 + 1e-6 * std::abs(N(i, j))));
              }
          }
}

// The rates are the time derivatives of range, azimuth and elevation of a moving target.
TEST_CASE("radar-state rates are geometry derivatives") {
  for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    const double sign = conv == AzimuthConvention::NorthClockwise ? -1.0 : 1.0;
    const Vec3 p(-3e5, 8e5, 9e4), v(2000.0, -5000.0, 700.0);
    rx::State X = rx::State::Zero();
    for (int a = 0; a < 3; ++a) {
      X(rx::pos(a)) = p(a);
      X(rx::vel(a)) = v(a);
    }
    const rx::Rates k = rx::rates(X, sign);
    const double h = 1e-3;
    const Vec3 d = (enu_to_spherical(p + h * v, conv) - enu_to_spherical(p - h * v, conv)) / (2 * h);
    CHECK(k.range == Approx(d(0)).epsilon(1e-8));
    CHECK(k.azimuth == Approx(d(1)).epsilon(1e-7));
    CHECK(k.elevation == Approx(d(2)).epsilon(1e-7));
  }
}

// Constant acceleration: Adams-Bashforth advances the position exactly, Euler lags by T^2 a / 2
// per step; velocities extrapolate the acceleration exactly in both.
TEST_CASE("position update euler and adams-bashforth") {
  const double T = 0.1, a = 20.0;
  rx::State X = rx::State::Zero();
  X(rx::pos(0)) = 1e6;
  X(rx::pos(1)) = 1e5;
  X(rx::vel(0)) = 100.0;
  X(rx::prev(0)) = 100.0 - a * T;
  X(rx::kRange) = std::hypot(1e6, 1e5);
  rx::Model m;
  m.position = rx::Position::AdamsBashforth2;
  const rx::State Y = rx::propagate(X, T, m);
  CHECK(Y(rx::pos(0)) == Approx(1e6 + 100.0 * T + 0.5 * a * T * T).epsilon(1e-15));
  CHECK(Y(rx::vel(0)) == Approx(100.0 + a * T).epsilon(1e-15));
  CHECK(Y(rx::prev(0)) == 100.0);
  m.position = rx::Position::Euler;
  CHECK(rx::propagate(X, T, m)(rx::pos(0)) == Approx(1e6 + 100.0 * T).epsilon(1e-15));
}
