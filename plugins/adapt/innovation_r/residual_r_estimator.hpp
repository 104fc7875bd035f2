// Purpose: paper 001's residual-based moving-average estimate of the measurement noise R (eq 28-32), kept symmetric positive definite.
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace trackflow::adapt {

// Raises the eigenvalues of R that lie below the floor, in two steps:
// 1. relative: R >= ratio² R_nominal (Loewner order), done on M = L⁻¹ R L⁻ᵀ with R_nominal = L Lᵀ,
//    eigenvalues of M raised to ratio². It scales with range and keeps the nominal's shape
//    (range vs cross-range), so a few small residuals cannot make the filter trust one direction
//    far more than the sensor ever could. Skipped if R_nominal is not positive definite.
// 2. absolute: every eigenvalue of R at least floor_sigma² (a last guard, whatever the nominal).
// Returns true if either step changed R.
inline bool apply_floor(Mat3& R, const Mat3& nominal, double ratio, double floor_sigma) {
  bool changed = false;
  const Eigen::LLT<Mat3> llt(nominal);
  if (ratio > 0.0 && nominal.allFinite() && llt.info() == Eigen::Success) {
    const Mat3 L = llt.matrixL();
    const Mat3 Linv = L.triangularView<Eigen::Lower>().solve(Mat3::Identity());
    Mat3 M = Linv * R * Linv.transpose();
    M = 0.5 * (M + M.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<Mat3> es(M);
    Vec3 lambda = es.eigenvalues();
    const double lo = ratio * ratio;
    if (lambda.minCoeff() < lo) {
      lambda = lambda.cwiseMax(lo);
      M = es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
      R = L * M * L.transpose();
      R = 0.5 * (R + R.transpose()).eval();
      changed = true;
    }
  }
  const double lo = floor_sigma * floor_sigma;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(R);
  Vec3 lambda = es.eigenvalues();
  if (lambda.minCoeff() < lo) {
    lambda = lambda.cwiseMax(lo);
    R = es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
    R = 0.5 * (R + R.transpose()).eval();
    changed = true;
  }
  return changed;
}

struct EstimatorSettings {
  int window = 20;             // L of eq 31 (the paper does not give it)
  double floor_ratio = 0.1;    // R̂ >= floor_ratio² × the measurement's own R
  double floor_sigma = 1e-3;   // m; every eigenvalue of R̂ >= floor_sigma²
  bool add_posterior = true;   // R_s = Δz Δzᵀ + H P⁺ Hᵀ (unbiased); false: − as printed in eq 28
  int warmup = 50;             // residuals ignored before the average starts (0: the paper)
};

// Eq 28-32 with Δz = z − H x⁺ the post-update residual and H P⁺ Hᵀ the updated position
// covariance in ENU (for the decoupled filter that is H D2 P̄⁺ D2ᵀ Hᵀ, eq 28; for a filter whose
// covariance is already Cartesian, D2 = I). For the optimal gain, Δz = (I − H K) ν = R S⁻¹ ν, so
// E[Δz Δzᵀ] = R S⁻¹ R = R − H P⁺ Hᵀ: the unbiased single-step estimate is Δz Δzᵀ + H P⁺ Hᵀ,
// which is also positive definite by construction. Eq 28 prints a minus sign; that form
// converges to 2 R S⁻¹ R − R = R (R − H P⁻ Hᵀ) S⁻¹ (scalar case): below R, and negative where
// H P⁻ Hᵀ exceeds R.
// Eq 32 as printed, (R_f + R_fᵀ)/2 + (R_f − R_fᵀ)/2, equals R_f; the symmetric part is meant.
// Warm-up: the first residuals after initialisation carry the initial-state error (two-point
// velocity errors are ~ σ√2/T), which the average would read as measurement noise; a larger R̂
// then lowers the gains, the state error persists and feeds R̂ again: a loop that diverged in
// our runs of paper 001's SCN.2 and SCN.3 (docs/papers/001-rbs-landing.md). For the first
// `warmup` residuals R̂ is the latest measurement's own R and the filter keeps its own R
// (adapting() is false); the average starts from there.
class ResidualREstimator {
 public:
  explicit ResidualREstimator(EstimatorSettings s = {}) : s_(s) {}

  bool started() const { return started_; }
  // During the warm-up R̂ is the measurement's own R times this (an estimate of the noise factor
  // squared that does not come from residuals; 1: the measurement's own R).
  void set_warmup_scale(double k2) { warmup_scale_ = k2; }
  double warmup_scale() const { return warmup_scale_; }
  bool adapting() const { return started_ && seen_ >= s_.warmup; }
  const Mat3& estimate() const { return R_; }
  // The measurements' own R averaged with the same window: what R̂ tends to if the sensor's
  // reported noise is right (the reference for the noise-factor estimate).
  const Mat3& nominal_average() const { return nominal_; }

  void start(const Mat3& first_nominal) {
    R_ = 0.5 * (first_nominal + first_nominal.transpose());
    nominal_ = R_;
    started_ = true;
    seen_ = 0;
    apply_floor(R_, nominal_, s_.floor_ratio, s_.floor_sigma);
  }

  // One residual; returns true if the floor was active.
  bool update(const Vec3& residual, const Mat3& posterior_position_cov, const Mat3& nominal) {
    if (seen_ < s_.warmup) {
      ++seen_;
      nominal_ = 0.5 * (nominal + nominal.transpose());
      R_ = warmup_scale_ * nominal_;
      return apply_floor(R_, nominal, s_.floor_ratio, s_.floor_sigma);
    }
    const double w = 1.0 / static_cast<double>(s_.window);
    Mat3 Rs = residual * residual.transpose();
    if (s_.add_posterior)
      Rs += posterior_position_cov;
    else
      Rs -= posterior_position_cov;
    R_ += w * (Rs - R_);
    R_ = 0.5 * (R_ + R_.transpose()).eval();
    nominal_ += w * (0.5 * (nominal + nominal.transpose()) - nominal_);
    return apply_floor(R_, nominal, s_.floor_ratio, s_.floor_sigma);
  }

 private:
  EstimatorSettings s_;
  Mat3 R_ = Mat3::Zero();
  Mat3 nominal_ = Mat3::Zero();
  bool started_ = false;
  int seen_ = 0;
  double warmup_scale_ = 1.0;
};

}  // namespace trackflow::adapt
