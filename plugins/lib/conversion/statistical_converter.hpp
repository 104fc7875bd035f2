// Purpose: the Component shared by the statistical convert.* plugins: input checks, sensor offset, range rate, symmetrisation.
#pragma once

#include "conversion_moments.hpp"

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace trackflow::conversion {

using ConversionFn = ConvertedPosition (*)(double r, double az, double el, const SphericalVariances&,
                                           AzimuthConvention);

// Converts spherical measurements [r, az, el(, ρ)] with `convert`. Only the diagonal of the
// (r, az, el) covariance is used: the three papers assume independent errors. Measurements
// whose errors are correlated anyway are counted and reported as a warning at the end of the run. Range rate ρ is
// measured directly, so its value and variance pass unchanged; its covariance with the
// position is the Stein's-lemma term of ConvertedPosition (zero when the input has none).
class StatisticalConverter final : public Component {
 public:
  StatisticalConverter(std::string type, std::string node, ConversionFn convert)
      : type_(std::move(type)), node_(std::move(node)), convert_(convert) {}

  void start_run(const RunContext& ctx) override {
    diagnostics_ = ctx.diagnostics;
    correlated_ = 0;
    largest_correlation_ = 0.0;
  }

  std::unique_ptr<RunResult> end_run() override {
    if (correlated_ > 0 && diagnostics_)
      diagnostics_->warn(node_, std::to_string(correlated_) +
                                    " measurement(s) had correlated (r, az, el) errors (largest |rho| = " +
                                    std::to_string(largest_correlation_) + "); " + type_ +
                                    " used only their variances");
    return nullptr;
  }

  void on_measurement(const Measurement& in, int) override {
    if (in.frame == Frame::Cartesian || !in.valid) {
      out.emit(in);  // already Cartesian, or nothing to convert: pass on unchanged
      return;
    }
    if (!in.sensor_level) throw DataError(type_ + " (node '" + node_ + "'): " + tilted_sensor_message(in));
    check(in);
    note_correlation(in);
    const int n = static_cast<int>(in.value.size());
    const double r = in.value(0), az = in.value(1), el = in.value(2);
    const SphericalVariances v{in.covariance(0, 0), in.covariance(1, 1), in.covariance(2, 2)};
    const ConvertedPosition cp = convert_(r, az, el, v, in.azimuth);

    m_ = in;
    m_.frame = Frame::Cartesian;
    m_.value.head<3>() = cp.position + in.sensor_position;
    m_.covariance.setZero();
    m_.covariance.topLeftCorner<3, 3>() = cp.covariance;
    if (n == 4) {
      m_.value(3) = in.value(3);
      m_.covariance(3, 3) = in.covariance(3, 3);
      const Vec3 cross = cp.jacobian_scale.asDiagonal() * spherical_to_enu_jacobian(r, az, el, in.azimuth) *
                         in.covariance.block<3, 1>(0, 3);
      m_.covariance.block<3, 1>(0, 3) = cross;
      m_.covariance.block<1, 3>(3, 0) = cross.transpose();
    }
    // Exact symmetry for downstream Cholesky factorisations.
    m_.covariance = 0.5 * (m_.covariance + m_.covariance.transpose()).eval();
    out.emit(m_);
  }

 private:
  // Bad data is reported, never turned into NaN downstream. Only runs the string code on failure.
  void check(const Measurement& in) const {
    const int n = static_cast<int>(in.value.size());
    const int expected = in.has_range_rate ? 4 : 3;
    if (n != expected || in.covariance.rows() != n || in.covariance.cols() != n)
      fail(in, "has " + std::to_string(n) + " values and a " + std::to_string(in.covariance.rows()) + "x" +
                   std::to_string(in.covariance.cols()) + " covariance; expected " + std::to_string(expected) +
                   (in.has_range_rate ? " (r, az, el, range rate)" : " (r, az, el)") + " and a matching covariance");
    if (!in.value.allFinite() || !in.covariance.allFinite()) fail(in, "has a non-finite value or covariance");
    for (int i = 0; i < n; ++i)
      if (in.covariance(i, i) < 0.0) fail(in, "has a negative variance at index " + std::to_string(i));
  }
  void note_correlation(const Measurement& in) {
    double largest = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        const double d = std::sqrt(in.covariance(i, i) * in.covariance(j, j));
        if (d > 0.0) largest = std::max(largest, std::abs(in.covariance(i, j)) / d);
      }
    if (largest > 1e-9) {
      ++correlated_;
      largest_correlation_ = std::max(largest_correlation_, largest);
    }
  }
  [[noreturn]] void fail(const Measurement& in, const std::string& what) const {
    throw DataError(type_ + " (node '" + node_ + "'): spherical measurement at t=" + std::to_string(in.time) +
                    " s from sensor " + std::to_string(in.sensor) + " " + what);
  }

  std::string type_;
  std::string node_;
  ConversionFn convert_;
  Measurement m_;
  Diagnostics* diagnostics_ = nullptr;
  long long correlated_ = 0;
  double largest_correlation_ = 0.0;
};

}  // namespace trackflow::conversion
