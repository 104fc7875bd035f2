// Purpose: a detection against a track's predicted measurement — the residual (azimuth wrapped), its NIS through the Cholesky factor of S, the chi-square gate (and its gate_probability parameter) and the Gaussian log-likelihood — for every associator.
#pragma once

#include <trackflow/estimator.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <Eigen/Cholesky>

#include <cmath>
#include <numbers>

namespace trackflow::association {

// One track's predicted measurement, factorised once per scan: NIS and likelihood of each
// detection then cost one triangular solve.
class PredictedGate {
 public:
  // false when S is not positive definite (the track takes no detection).
  bool set(const PredictedMeasurement& p, Frame frame) {
    z_ = &p.z;
    azimuth_ = has_azimuth(frame);
    dim_ = static_cast<int>(p.z.size());
    llt_.compute(p.S);
    log_det_ = p.log_det_S;
    return llt_.info() == Eigen::Success && std::isfinite(log_det_);
  }

  int dim() const { return dim_; }

  // nu' S^-1 nu of detection value `value` (its leading dim() elements); the azimuth residual of a
  // spherical or polar measurement is wrapped to (-pi, pi].
  double nis(const MeasVec& value) const {
    MeasVec nu = value.head(dim_) - *z_;
    if (azimuth_) nu(1) = wrap_angle(nu(1));
    const MeasVec w = llt_.matrixL().solve(nu);
    return w.squaredNorm();
  }

  // log N(nu; 0, S) = -(NIS + log det S + dim log 2 pi) / 2.
  double log_likelihood(double nis) const {
    return -0.5 * (nis + log_det_ + dim_ * std::log(2.0 * std::numbers::pi));
  }

 private:
  const MeasVec* z_ = nullptr;
  bool azimuth_ = false;  // value(1) is an azimuth (Spherical, Polar): its residual wraps
  int dim_ = 0;
  Eigen::LLT<MeasCov> llt_;
  double log_det_ = 0.0;
};

// The gate probability every associator declares the same way.
inline ParamSpec gate_probability_param() {
  return ParamSpec::real("gate_probability", Dimension{}, "P_G: probability that a target's detection falls in its gate")
      .def("0.99")
      .positive()
      .at_most(0.999999);
}

}  // namespace trackflow::association
