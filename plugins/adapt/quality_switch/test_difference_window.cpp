// Purpose: tests of the windowed RMS of successive differences (hand computations, wrap, detrend, sample statistics) and of the grade thresholds.
#include "difference_window.hpp"

#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

using namespace trackflow;
using adapt::DifferenceWindow;
using adapt::Grade;
using adapt::grade_of;

TEST_CASE("RMS of the last n differences by hand") {
  DifferenceWindow w(3);
  const double z[] = {1.0, 3.0, 2.0, 6.0, 4.0};
  w.add(z[0]);
  CHECK(w.differences() == 0);
  w.add(z[1]);  // d = 2
  w.add(z[2]);  // d = -1
  CHECK_FALSE(w.full());
  CHECK(w.rms() == Approx(std::sqrt((4.0 + 1.0) / 2.0)));  // what is held so far
  w.add(z[3]);  // d = 4: full
  CHECK(w.full());
  CHECK(w.rms() == Approx(std::sqrt((4.0 + 1.0 + 16.0) / 3.0)));
  w.add(z[4]);  // d = -2; the oldest (2) leaves
  CHECK(w.rms() == Approx(std::sqrt((1.0 + 16.0 + 4.0) / 3.0)));
}

TEST_CASE("reset: no difference is taken across the gap") {
  DifferenceWindow w(2);
  for (double z : {0.0, 1.0, 2.0}) w.add(z);
  REQUIRE(w.full());
  w.reset();
  CHECK(w.differences() == 0);
  w.add(1000.0);  // first sample after the gap: no difference with 2.0
  CHECK(w.differences() == 0);
  w.add(1003.0);
  w.add(1006.0);
  CHECK(w.full());
  CHECK(w.rms() == Approx(3.0));
}

TEST_CASE("azimuth differences wrap across the pi seam") {
  constexpr double pi = std::numbers::pi;
  DifferenceWindow az(2, /*wrap=*/true), plain(2);
  for (double z : {pi - 0.01, -pi + 0.01, -pi + 0.03}) {
    az.add(z);
    plain.add(z);
  }
  CHECK(az.rms() == Approx(0.02).epsilon(1e-9));  // both steps are +0.02 rad
  CHECK(plain.rms() > 4.0);
}

TEST_CASE("detrend removes a constant rate and RMS keeps it") {
  DifferenceWindow plain(4), centred(4, false, true);
  // A ramp of slope 5 per sample plus +-1 alternating: differences 5 +- 2 alternating.
  for (int i = 0; i < 9; ++i) {
    const double z = 5.0 * i + (i % 2 ? 1.0 : -1.0);
    plain.add(z);
    centred.add(z);
  }
  // Last four differences (z = 19, 26, 29, 36, 39): 7, 3, 7, 3.
  CHECK(plain.rms() == Approx(std::sqrt((9.0 + 49.0 + 9.0 + 49.0) / 4.0)));
  CHECK(centred.rms() == Approx(2.0));
}

// white noise: E[RMSE^2] = 2 sigma^2, detrended 2 sigma^2 (1 - 1/n^2), whatever the rate
TEST_CASE("white noise RMSE^2 expectation with any rate") {
  const int n = 10, windows = 20000;
  const double sigma = 0.3, rate = 7.0;
  Rng rng(11);
  double sum_plain = 0.0, sum_sq_plain = 0.0, sum_centred = 0.0, sum_sq_centred = 0.0;
  for (int k = 0; k < windows; ++k) {
    // Independent windows: n + 1 fresh samples each.
    DifferenceWindow plain(n), centred(n, false, true);
    for (int i = 0; i <= n; ++i) {
      const double w = sigma * rng.normal();
      plain.add(w);
      centred.add(rate * i + w);
    }
    const double a = plain.rms() * plain.rms(), b = centred.rms() * centred.rms();
    sum_plain += a;
    sum_sq_plain += a * a;
    sum_centred += b;
    sum_sq_centred += b * b;
  }
  const double N = windows;
  const double mean_plain = sum_plain / N, mean_centred = sum_centred / N;
  const double se_plain = std::sqrt((sum_sq_plain / N - mean_plain * mean_plain) / N);
  const double se_centred = std::sqrt((sum_sq_centred / N - mean_centred * mean_centred) / N);
  const double s2 = sigma * sigma;
  CHECK(std::abs(mean_plain - 2.0 * s2) < 4.0 * se_plain);
  CHECK(std::abs(mean_centred - 2.0 * s2 * (1.0 - 1.0 / (n * n))) < 4.0 * se_centred);
  // The standard errors are small enough for the test to mean something (about 0.5 %).
  CHECK(se_plain < 0.01 * 2.0 * s2);
}

// grade thresholds: BEST up to l1 M inclusive, NORMAL up to l2 M inclusive, WORST beyond
TEST_CASE("grade thresholds l1 M and l2 M are inclusive") {
  const double M = 2.2254, inf = std::numeric_limits<double>::infinity();
  CHECK(grade_of(0.0, M, 1, 2) == Grade::Best);
  CHECK(grade_of(0.5 * M, M, 1, 2) == Grade::Best);
  CHECK(grade_of(M, M, 1, 2) == Grade::Best);
  CHECK(grade_of(std::nextafter(M, inf), M, 1, 2) == Grade::Normal);
  CHECK(grade_of(2.0 * M, M, 1, 2) == Grade::Normal);
  CHECK(grade_of(std::nextafter(2.0 * M, inf), M, 1, 2) == Grade::Worst);
  CHECK(grade_of(3.0 * M, M, 1, 2) == Grade::Worst);
  CHECK(grade_of(1e6 * M, M, 1, 2) == Grade::Worst);
  // Other limits, e.g. reading Table 1 as BEST below 0.5 M.
  CHECK(grade_of(0.6 * M, M, 0.5, 2) == Grade::Normal);
  CHECK(grade_of(0.5 * M, M, 0.5, 2) == Grade::Best);
}
