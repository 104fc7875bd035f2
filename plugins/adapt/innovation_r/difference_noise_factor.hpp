// Purpose: the noise factor of converted position measurements from their second differences, independent of any filter state (adapt.innovation_r's warm-up estimate).
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Cholesky>

#include <cmath>
#include <limits>

namespace trackflow::adapt {

// For equally spaced measurements z_k = p(t_k) + w_k of a target moving at constant velocity,
// the second difference d_k = z_k − 2 z_{k−1} + z_{k−2} holds no motion at all, so
// E[d dᵀ] = R_k + 4 R_{k−1} + R_{k−2} whatever the track. Against the measurements' own
// (reported) covariances N, the noise factor squared k² = tr(B⁻¹ A)/3 with A = Σ d dᵀ,
// B = Σ (N_k + 4 N_{k−1} + N_{k−2}) is the mean generalised eigenvalue of the actual noise over the
// reported one: 1 for a radar that reports its noise, 25 for paper 001's SCN.2. It needs no
// filter, so it cannot absorb the start-up state error the way residuals do. A manoeuvre adds
// its acceleration change (T² Δa) to d: small against the noise at radar rates.
class DifferenceNoiseFactor {
 public:
  void reset() {
    n_ = 0;
    pairs_ = 0;
    A_.setZero();
    B_.setZero();
  }

  // A valid converted measurement; a gap (invalid one) or an uneven time step restarts the
  // differencing (but keeps the sums).
  void add(double t, const Vec3& z, const Mat3& N) {
    const bool even = n_ >= 2 && std::abs((t - t_[1]) - (t_[1] - t_[0])) <= 1e-9 * std::abs(t - t_[1]);
    if (even) {
      const Vec3 d = z - 2.0 * z_[1] + z_[0];
      A_ += d * d.transpose();
      B_ += N + 4.0 * N_[1] + N_[0];
      ++pairs_;
    }
    if (n_ >= 2 && !even) n_ = 0;
    if (n_ == 2) {  // shift
      z_[0] = z_[1];
      N_[0] = N_[1];
      t_[0] = t_[1];
      n_ = 1;
    }
    z_[n_] = z;
    N_[n_] = N;
    t_[n_] = t;
    ++n_;
  }
  void gap() { n_ = 0; }

  int samples() const { return pairs_; }
  // k² (1 when the reported noise is right); NaN without samples.
  double variance_factor() const {
    if (pairs_ == 0) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::LLT<Mat3> llt(B_);
    if (llt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
    return llt.solve(A_).trace() / 3.0;
  }

 private:
  int n_ = 0, pairs_ = 0;
  Vec3 z_[2];
  Mat3 N_[2];
  double t_[2] = {};
  Mat3 A_ = Mat3::Zero(), B_ = Mat3::Zero();
};

}  // namespace trackflow::adapt
