// Purpose: tests of the second-difference noise factor: unbiased for any constant-velocity motion, k² of a degraded sensor, gaps and uneven steps.
#include "difference_noise_factor.hpp"

#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace trackflow;
using adapt::DifferenceNoiseFactor;

namespace {

// n measurements at 10 Hz of a constant-velocity target, noise k times the reported sigmas.
DifferenceNoiseFactor measure(int n, double k, const Vec3& sigma, std::uint64_t seed, int gap_every = 0) {
  Rng rng(seed);
  DifferenceNoiseFactor f;
  const Vec3 p0(4000, -60, 210), v(-30, 0.5, -1.6);
  const Mat3 N = sigma.cwiseAbs2().asDiagonal();
  for (int i = 0; i < n; ++i) {
    if (gap_every > 0 && i % gap_every == gap_every - 1) {
      f.gap();
      continue;
    }
    const double t = 0.1 * i;
    const Vec3 w(rng.normal() * sigma(0), rng.normal() * sigma(1), rng.normal() * sigma(2));
    f.add(t, p0 + v * t + k * w, N);
  }
  return f;
}

}  // namespace

TEST_CASE("second differences give k2 of a misreporting sensor") {
  // n pairs of 3-D second differences: k² is a mean of 3n correlated chi-square terms; 4 standard
  // deviations of an independent estimate, 4 sqrt(2 / (3 n)) k², with n = 3000 is 6 % of k²,
  // doubled for the correlation of neighbouring differences.
  for (double k : {1.0, 5.0, 10.0}) {
    const DifferenceNoiseFactor f = measure(3002, k, Vec3(3, 2, 1), 7);
    REQUIRE(f.samples() == 3000);
    CHECK(std::abs(f.variance_factor() / (k * k) - 1.0) < 0.12);
  }
}

TEST_CASE("second differences ignore constant-velocity motion") {
  // No noise at all: the factor is 0 to rounding, whatever the target does at constant velocity.
  DifferenceNoiseFactor f;
  const Mat3 N = Mat3::Identity();
  for (int i = 0; i < 50; ++i) f.add(0.1 * i, Vec3(1e4 - 250.0 * 0.1 * i, 3e3 + 40.0 * 0.1 * i, 500), N);
  CHECK(f.variance_factor() < 1e-12);
}

TEST_CASE("gaps and uneven steps restart the differencing") {
  DifferenceNoiseFactor empty;
  CHECK(std::isnan(empty.variance_factor()));
  // A gap every 5 samples: each run of 4 valid samples gives 2 second differences.
  const DifferenceNoiseFactor f = measure(50, 1.0, Vec3(1, 1, 1), 3, 5);
  CHECK(f.samples() == 20);
  DifferenceNoiseFactor uneven;
  const Mat3 N = Mat3::Identity();
  uneven.add(0.0, Vec3::Zero(), N);
  uneven.add(0.1, Vec3::Zero(), N);
  uneven.add(0.3, Vec3::Zero(), N);  // 0.2 s after 0.1 s: not a second difference
  CHECK(uneven.samples() == 0);
  uneven.add(0.5, Vec3::Zero(), N);
  uneven.add(0.7, Vec3::Zero(), N);
  CHECK(uneven.samples() == 1);
}
