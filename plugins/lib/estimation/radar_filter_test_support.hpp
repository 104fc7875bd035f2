// Purpose: test helpers shared by the Cartesian radar filters' tests: noisy radar measurements from geometry.hpp, truth process noise, NEES, chi-square bands, covariance checks, a filter under test.
#pragma once

#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "plugin_fixture.hpp"

namespace trackflow::filter_test {

struct RadarNoise {
  double range = 10.0, azimuth = 1e-3, elevation = 1e-3, range_rate = 0.5;
};

// A radar measurement built with geometry.hpp only (independent of spherical_measurement.hpp).
inline Measurement radar(double t, const Vec3& pos, const Vec3& vel, const Vec3& sensor, const RadarNoise& s,
                         Rng* rng, bool with_rr, AzimuthConvention c = AzimuthConvention::NorthClockwise) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Spherical;
  m.azimuth = c;
  m.sensor_position = sensor;
  m.has_range_rate = with_rr;
  const int n = with_rr ? 4 : 3;
  m.value.resize(n);
  const Vec3 rae = enu_to_spherical(pos - sensor, c);
  m.value.head<3>() = rae;
  if (with_rr) m.value(3) = range_rate(pos - sensor, vel);
  m.covariance = MeasCov::Zero(n, n);
  const double sig[4] = {s.range, s.azimuth, s.elevation, s.range_rate};
  for (int i = 0; i < n; ++i) {
    m.covariance(i, i) = sig[i] * sig[i];
    if (rng) m.value(i) += sig[i] * rng->normal();
  }
  if (rng) m.value(1) = wrap_angle(m.value(1));
  return m;
}

// Exact discretisation of a continuous white-noise model, per axis: w ~ N(0, Qa).
template <int K>
inline void add_process_noise(const Eigen::Matrix<double, K, K>& Qa, Eigen::Matrix<double, K, 1>* axes, Rng& rng) {
  const Eigen::Matrix<double, K, K> L = Qa.llt().matrixL();
  for (int a = 0; a < 3; ++a) {
    Eigen::Matrix<double, K, 1> w;
    for (int i = 0; i < K; ++i) w(i) = rng.normal();
    axes[a] += L * w;
  }
}

inline double nees(const Estimate& e, const Vec3& p, const Vec3& v) {
  Vec6 err;
  err << e.enu.head<3>() - p, e.enu.tail<3>() - v;
  return err.dot(e.enu_covariance.ldlt().solve(err));
}

// 99 % two-sided band of chi2(k)/k (Wilson-Hilferty; accurate to < 1e-3 for k >= 100).
inline std::pair<double, double> chi2_band(double k) {
  const double z = 2.5758, c = 2.0 / (9.0 * k);
  return {std::pow(1 - c - z * std::sqrt(c), 3), std::pow(1 - c + z * std::sqrt(c), 3)};
}

inline bool symmetric_pd(const StateCov& P) {
  if (!P.allFinite()) return false;
  if ((P - P.transpose()).norm() > 1e-12 * P.norm()) return false;
  return Eigen::LLT<Eigen::MatrixXd>(Eigen::MatrixXd(P)).info() == Eigen::Success;
}

// A filter of `type` created through the plugin loader, its outputs collected.
struct FilterRun {
  std::shared_ptr<Component> filter;
  test::Collector out;
  Diagnostics diag;
  FilterRun(const std::string& type, const std::string& params, std::uint64_t run = 0, const std::string& node = "node")
      : filter(test::make(type, params, node)) {
    out.attach_to(*filter);
    filter->start_run({run, 1, &diag});
  }
  const Estimate& feed(const Measurement& m) {
    filter->on_measurement(m, 0);
    return out.estimates.back();
  }
};

}  // namespace trackflow::filter_test
