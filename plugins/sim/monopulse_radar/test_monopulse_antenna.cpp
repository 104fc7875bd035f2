// Purpose: tests of the four-horn monopulse model (eq 2-1..2-12): horn pattern, slope, symmetries and the non-linear error curve.
#include "monopulse_antenna.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace trackflow::sim;

namespace {

// eq 2-1 written out again, independently of the plugin's series handling (never near 2kx = 1 here).
long double pattern_ref(long double x, long double k) {
  const long double pi = std::numbers::pi_v<long double>;
  return std::cos(pi * k * x) / (1.0L - 4.0L * k * k * x * x);
}

// eq 2-6..2-12 written out: d_az / S at (theta, phi).
long double ratio_az_ref(long double th, long double ph) {
  const long double s = 0.358L, k = 1.19L;
  auto v = [&](long double a, long double b) { return pattern_ref(std::sqrt(a * a + b * b), k); };
  const long double A = v(th - s, ph + s), B = v(th - s, ph - s), C = v(th + s, ph + s), D = v(th + s, ph - s);
  return ((C + D) - (A + B)) / (A + B + C + D);
}

}  // namespace

// k = 1.19 puts the half-power point (1/sqrt(2) in voltage) at half a beamwidth: that is what makes
// angles in eq 2-1 beamwidth units. 0.706658 vs 0.707107: within 0.1 %.
TEST_CASE("horn pattern is 3 dB down at half a beamwidth") {
  CHECK(horn_pattern(0.0, 1.19) == Approx(1.0).epsilon(1e-15));
  CHECK(horn_pattern(0.5, 1.19) == Approx(1.0 / std::sqrt(2.0)).epsilon(1e-3));
  CHECK(horn_pattern(-0.5, 1.19) == horn_pattern(0.5, 1.19));
}

// At 2kx = 1 eq 2-1 is 0/0 with limit pi/4; the series must join the formula smoothly on both sides.
TEST_CASE("horn pattern is smooth through its 0 over 0 point") {
  const double k = 1.19, x1 = 1.0 / (2.0 * k);
  CHECK(horn_pattern(x1, k) == Approx(std::numbers::pi / 4).epsilon(1e-12));
  for (double d : {-2e-4, -5e-5, 5e-5, 2e-4}) {
    const double x = x1 * (1.0 + d);
    const double y = 2.0 * k * x;
    const double formula = std::cos(std::numbers::pi * y / 2) / (1.0 - y * y);
    CHECK(horn_pattern(x, k) == Approx(formula).epsilon(1e-7));
  }
}

TEST_CASE("horn pattern derivative matches differences") {
  const double k = 1.19, h = 1e-6;
  for (double x : {0.05, 0.3, 0.42, 0.506, 0.7, 0.9}) {
    const double numeric = (horn_pattern(x + h, k) - horn_pattern(x - h, k)) / (2 * h);
    CHECK(horn_pattern_derivative(x, k) == Approx(numeric).epsilon(1e-6));
  }
}

// Slope of d_az/S at boresight: V'(r0) / (sqrt(2) V(r0)), r0 = sqrt(2) squint; the same number as a
// numerical derivative of the independently written eq 2-6..2-12, negative with the paper's labels.
TEST_CASE("boresight slope equals its closed form") {
  const FourHornMonopulse m;
  const double r0 = std::sqrt(2.0) * 0.358;
  CHECK(m.slope() == Approx(horn_pattern_derivative(r0, 1.19) / (std::sqrt(2.0) * horn_pattern(r0, 1.19))).epsilon(1e-14));
  const long double h = 1e-6L;
  const double numeric = static_cast<double>((ratio_az_ref(h, 0) - ratio_az_ref(-h, 0)) / (2 * h));
  CHECK(m.slope() == Approx(numeric).epsilon(1e-7));
  CHECK(m.slope() == Approx(-1.0489).margin(1e-4));
}

// d_az is odd in theta and even in phi, d_el the reverse; both vanish at boresight; S is even in both.
TEST_CASE("error signals have the four-horn symmetries") {
  const FourHornMonopulse m;
  double az = 1, el = 1;
  m.error_signals(0, 0, az, el);
  CHECK(az == Approx(0).margin(1e-15));
  CHECK(el == Approx(0).margin(1e-15));
  for (double th : {0.05, 0.2}) {
    for (double ph : {0.0, 0.1, 0.3}) {
      double a1, e1, a2, e2, a3, e3;
      m.error_signals(th, ph, a1, e1);
      m.error_signals(-th, ph, a2, e2);
      m.error_signals(th, -ph, a3, e3);
      CHECK(a2 == Approx(-a1).epsilon(1e-12));
      CHECK(a3 == Approx(a1).epsilon(1e-12));
      CHECK(e2 == Approx(e1).margin(1e-15));
      CHECK(e3 == Approx(-e1).margin(1e-15));
      CHECK(m.channels(-th, -ph).sum == Approx(m.channels(th, ph).sum).epsilon(1e-14));
      // The plugin's channels agree with eq 2-6..2-12 written out here.
      CHECK(a1 == Approx(static_cast<double>(ratio_az_ref(th, ph))).epsilon(1e-12));
    }
  }
}

// The reported offset (error signal / boresight slope) equals the true one to first order; being odd,
// its error grows as u^3: doubling u multiplies it by 8 (to the next, u^5, order). At 0.3 beamwidths
// the antenna over-reports by 3.48e-3 beamwidths (1.2 %), with a cross-coupling from the other axis.
TEST_CASE("reported offset is non-linear off boresight") {
  const FourHornMonopulse m;
  auto error_at = [&](double u) {
    double a, e;
    m.reported_offset(u, 0.0, a, e);
    CHECK(e == Approx(0).margin(1e-15));
    return a - u;
  };
  CHECK(std::abs(error_at(0.01)) < 2e-7);
  CHECK(error_at(0.1) > 0);
  CHECK(error_at(0.2) / error_at(0.1) == Approx(8.0).epsilon(0.02));
  CHECK(error_at(0.3) == Approx(static_cast<double>(ratio_az_ref(0.3L, 0) / m.slope()) - 0.3).epsilon(1e-9));
  CHECK(error_at(0.3) == Approx(3.481e-3).epsilon(1e-3));
  CHECK(error_at(-0.3) == Approx(-error_at(0.3)).epsilon(1e-12));
  double a_off, e_off;
  m.reported_offset(0.3, 0.2, a_off, e_off);
  CHECK(a_off - 0.3 > error_at(0.3));  // an elevation offset adds to the azimuth error (cross-coupling)
}
