// Purpose: tests of the typed filter–adapter contract (noise.hpp): the compatibility check and the per-channel q mappings (line-of-sight scaling by hand, the ENU diagonal against a numerically differentiated full J Q J').
#include <trackflow/geometry.hpp>
#include <trackflow/noise.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace trackflow;

namespace {

// d(x, y, z)/d(r, az, el) by central differences of spherical_to_enu.
Mat3 numerical_jacobian(double r, double az, double el, AzimuthConvention c) {
  Mat3 J;
  const double h[3] = {1e-3, 1e-7, 1e-7};
  for (int k = 0; k < 3; ++k) {
    Vec3 a(r, az, el), b(r, az, el);
    a(k) += h[k];
    b(k) -= h[k];
    J.col(k) = (spherical_to_enu(a(0), a(1), a(2), c) - spherical_to_enu(b(0), b(1), b(2), c)) / (2 * h[k]);
  }
  return J;
}

}  // namespace

TEST_CASE("line-of-sight PSDs scale angles by range terms") {
  const ChannelPsd q{0.01, 1e-13, 2e-13};
  const double r = 140e3, el = 0.3;
  const Vec3 los = line_of_sight_psd(q, r, el);
  CHECK(los(0) == 0.01);
  CHECK(los(1) == Approx(std::pow(r * std::cos(el), 2) * 1e-13));
  CHECK(los(2) == Approx(r * r * 2e-13));
}

TEST_CASE("ENU-axis PSDs are diag of J diag(q) J'") {
  const ChannelPsd q{0.03, 4e-13, 1e-13};
  for (auto conv : {AzimuthConvention::NorthClockwise, AzimuthConvention::XCounterClockwise}) {
    for (double az : {0.0, 0.7, 2.5, -1.9}) {
      for (double el : {0.0, 0.4, 1.2}) {
        const double r = 120e3;
        const Mat3 J = numerical_jacobian(r, az, el, conv);
        const Mat3 full = J * Vec3(q.range, q.azimuth, q.elevation).asDiagonal() * J.transpose();
        const Vec3 diag = enu_axis_psd(q, r, az, el, conv);
        INFO("az " << az << " el " << el);
        for (int i = 0; i < 3; ++i) CHECK(diag(i) == Approx(full(i, i)).epsilon(1e-6).margin(1e-12));
        // The trace is the line-of-sight total: a rotation of the line-of-sight PSDs.
        CHECK(diag.sum() == Approx(line_of_sight_psd(q, r, el).sum()).epsilon(1e-9));
      }
    }
  }
}

TEST_CASE("ENU-axis PSDs are exact for a northward LOS") {
  // north_clockwise, az = 0, el = 0: range along y, azimuth along x, elevation along z.
  const ChannelPsd q{0.05, 1e-12, 3e-12};
  const double r = 100e3;
  const Vec3 diag = enu_axis_psd(q, r, 0.0, 0.0, AzimuthConvention::NorthClockwise);
  CHECK(diag(0) == Approx(r * r * 1e-12));
  CHECK(diag(1) == Approx(0.05));
  CHECK(diag(2) == Approx(r * r * 3e-12));
}

TEST_CASE("noise_mismatch accepts a matching filter") {
  MeasCov R = MeasCov::Zero(3, 3);
  double q[3] = {1, 1, 1};
  const NoiseHandles offered{{&R, MeasurementSpace::Spherical},
                             {q, 3, NoiseKind::SpectralDensity, dim::jerk_psd, NoiseAxes::LineOfSight}};
  NoiseNeeds needs;
  needs.measurement = MeasurementSpace::Spherical;
  needs.process = true;
  needs.process_kind = NoiseKind::SpectralDensity;
  needs.process_dimension = dim::jerk_psd;
  needs.process_axes = mask(NoiseAxes::Enu) | mask(NoiseAxes::LineOfSight);
  CHECK(noise_mismatch(needs, offered, false).empty());
  needs.covariance = true;
  CHECK_THAT(noise_mismatch(needs, offered, false), Catch::Contains("state covariance"));
  CHECK(noise_mismatch(needs, offered, true).empty());
}

TEST_CASE("noise_mismatch names both sides") {
  MeasCov R = MeasCov::Zero(3, 3);
  double sigma[3] = {1, 1, 1};
  // filter.gain_transform's Singer sigma_m per ENU axis against a writer of jerk densities.
  const NoiseHandles singer{{&R, MeasurementSpace::Spherical},
                            {sigma, 3, NoiseKind::StandardDeviation, dim::acceleration, NoiseAxes::Enu}};
  NoiseNeeds needs;
  needs.measurement = MeasurementSpace::Spherical;
  needs.process = true;
  needs.process_dimension = dim::jerk_psd;
  needs.process_axes = mask(NoiseAxes::Enu);
  const std::string why = noise_mismatch(needs, singer, true);
  CHECK_THAT(why, Catch::Contains("spectral densities in m2/s5"));
  CHECK_THAT(why, Catch::Contains("3 standard deviations in m/s2, per ENU axis"));
  // R in another space.
  NoiseNeeds cartesian;
  cartesian.measurement = MeasurementSpace::CartesianPosition;
  CHECK_THAT(noise_mismatch(cartesian, singer, true), Catch::Contains("cartesian_position") || Catch::Contains("Cartesian"));
  CHECK_THAT(noise_mismatch(cartesian, singer, true), Catch::Contains("spherical"));
  // Nothing exposed.
  CHECK_THAT(noise_mismatch(cartesian, NoiseHandles{}, true), Catch::Contains("exposes no measurement noise"));
}
