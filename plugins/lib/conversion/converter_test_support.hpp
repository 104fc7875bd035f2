// Purpose: test-only helpers for the convert.* plugins: spherical test measurements, one-shot conversion, reference moments.
#pragma once

#include "gauss_hermite.hpp"

#include <trackflow/component.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <string>

namespace trackflow::test {

using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

// A spherical measurement with diagonal (r, az, el) errors; with range rate when `rr_var` > 0,
// whose covariance with (r, az, el) is `rr_cross`.
inline Measurement spherical_measurement(double r, double az, double el, const Vec3& sigmas, AzimuthConvention c,
                                         const Vec3& sensor = Vec3::Zero(), double rr = 0.0, double rr_var = 0.0,
                                         const Vec3& rr_cross = Vec3::Zero()) {
  Measurement m;
  m.time = 12.5;
  m.frame = Frame::Spherical;
  m.azimuth = c;
  m.sensor_position = sensor;
  m.has_range_rate = rr_var > 0.0;
  const int n = m.has_range_rate ? 4 : 3;
  m.value.resize(n);
  m.covariance = MeasCov::Zero(n, n);
  m.value.head<3>() << r, az, el;
  m.covariance.diagonal().head<3>() = sigmas.cwiseProduct(sigmas);
  if (m.has_range_rate) {
    m.value(3) = rr;
    m.covariance(3, 3) = rr_var;
    m.covariance.block<3, 1>(0, 3) = rr_cross;
    m.covariance.block<1, 3>(3, 0) = rr_cross.transpose();
  }
  return m;
}

// Feeds one measurement to `conv` and returns what it emitted (exactly one item expected).
class OneShot : public Component {
 public:
  void on_measurement(const Measurement& m, int) override {
    last = m;
    ++count;
  }
  Measurement convert(Component& conv, const Measurement& in) {
    link_ = {this, 0, 0xFF};
    conv.out.connect(&link_, 1);
    count = 0;
    conv.on_measurement(in, 0);
    return last;
  }
  Measurement last;
  int count = 0;

 private:
  Link link_;
};

// Sensor-relative ENU position of a spherical point (the map whose moments are the reference).
inline Vec3 enu_of(const Vec3& s, AzimuthConvention c) { return spherical_to_enu(s(0), s(1), s(2), c); }

// Spherical covariance (diagonal block) plus optional range-rate row, as a 4x4 matrix.
inline Mat4 spherical_covariance4(const Measurement& m) {
  Mat4 S = Mat4::Zero();
  const int n = static_cast<int>(m.value.size());
  S.topLeftCorner(n, n) = m.covariance;
  return S;
}

// E over t ~ N(m_pos, S_pos) (the truth given the measurement) of the moments of g(x') for
// x' ~ N((t, m_rest), S) (a new measurement given that truth): the "average true" moments
// the debiased and Mo's conversions are defined by. Returns E_t[E[g]] and E_t[Cov[g]].
template <int K, int D, class G>
Moments<K> averaged_truth_conditioned_moments(const Eigen::Matrix<double, D, 1>& meas,
                                              const Eigen::Matrix<double, D, D>& S, int order, G&& g) {
  Moments<K> avg;
  const Vec3 m_pos = meas.template head<3>();
  const Mat3 S_pos = S.template topLeftCorner<3, 3>();
  for_each_gauss_hermite<3>(m_pos, S_pos, order, [&](const Vec3& t, double w) {
    Eigen::Matrix<double, D, 1> centre = meas;
    centre.template head<3>() = t;
    const Moments<K> inner = gauss_hermite_moments<K, D>(centre, S, order, g);
    avg.mean += w * inner.mean;
    avg.covariance += w * inner.covariance;
  });
  return avg;
}

// Central-difference Jacobian of the sensor-relative ENU position w.r.t. (r, az, el).
inline Mat3 numerical_jacobian(const Vec3& s, AzimuthConvention c) {
  Mat3 J;
  for (int k = 0; k < 3; ++k) {
    Vec3 h = Vec3::Zero();
    h(k) = k == 0 ? 1e-3 : 1e-7;
    J.col(k) = (enu_of(s + h, c) - enu_of(s - h, c)) / (2.0 * h(k));
  }
  return J;
}

// Frobenius-relative difference, the tolerance measure of the matrix checks.
template <class A, class B>
double relative_difference(const A& got, const B& expected) {
  return (got - expected).norm() / expected.norm();
}

}  // namespace trackflow::test
