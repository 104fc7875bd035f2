// Purpose: the exact per-period draws of the white-acceleration and white-jerk deviations and the reading of their q.
#include "process_noise.hpp"

#include <Eigen/Cholesky>

#include <cmath>

namespace trackflow::sim {

WhiteAccelerationNoise::WhiteAccelerationNoise(const Vec3& q, double period)
    : period_(period), enabled_((q.array() > 0.0).any()) {
  // q [[T³/3, T²/2], [T²/2, T]] = L Lᵀ with l11 = √(q T³/3), l21 = (q T²/2) / l11 = √(3 q T)/2,
  // l22 = √(q T - l21²) = √(q T)/2: closed form, so no factorisation of a near-singular matrix.
  const double T = period;
  const Vec3 s = q.cwiseSqrt();
  l11_ = s * std::sqrt(T * T * T / 3.0);
  l21_ = s * (std::sqrt(3.0 * T) / 2.0);
  l22_ = s * (std::sqrt(T) / 2.0);
}

void WhiteAccelerationNoise::reset(std::uint64_t seed) {
  rng_.reseed(seed);
  dp_.setZero();
  dv_.setZero();
  mean_accel_.setZero();
}

void WhiteAccelerationNoise::step() {
  for (int i = 0; i < 3; ++i) {
    const double n1 = rng_.normal(), n2 = rng_.normal();
    const double wp = l11_[i] * n1, wv = l21_[i] * n1 + l22_[i] * n2;
    dp_[i] += period_ * dv_[i] + wp;
    dv_[i] += wv;
    mean_accel_[i] = wv / period_;
  }
}

WhiteJerkNoise::WhiteJerkNoise(const Vec3& q, double period)
    : scale_(q.cwiseSqrt()), period_(period), enabled_((q.array() > 0.0).any()) {
  // Q1 = D M D with D = diag(T^(5/2), T^(3/2), T^(1/2)) and the constant, well-conditioned
  // M = [[1/20, 1/8, 1/6], [1/8, 1/3, 1/2], [1/6, 1/2, 1]]: chol(Q1) = D chol(M), so the tiny
  // entries of Q1 at high rates (T⁵/20 = 5e-10 s⁵ at 40 Hz) never enter a factorisation.
  Eigen::Matrix3d M;
  M << 1.0 / 20, 1.0 / 8, 1.0 / 6, 1.0 / 8, 1.0 / 3, 1.0 / 2, 1.0 / 6, 1.0 / 2, 1.0;
  const Eigen::Matrix3d L = M.llt().matrixL();
  const double T = period;
  const Vec3 D(std::pow(T, 2.5), std::pow(T, 1.5), std::sqrt(T));
  chol_ = D.asDiagonal() * L;
}

void WhiteJerkNoise::reset(std::uint64_t seed) {
  rng_.reseed(seed);
  dp_.setZero();
  dv_.setZero();
  da_.setZero();
}

void WhiteJerkNoise::step() {
  const double T = period_;
  for (int i = 0; i < 3; ++i) {
    const Vec3 n(rng_.normal(), rng_.normal(), rng_.normal());
    const Vec3 w = scale_[i] * (chol_ * n);
    dp_[i] += T * dv_[i] + 0.5 * T * T * da_[i] + w[0];
    dv_[i] += T * da_[i] + w[1];
    da_[i] += w[2];
  }
}

Vec3 process_noise_q(const Params& params) {
  if (params.given("process_noise_q") && params.given("process_noise_q_enu"))
    throw params.error("process_noise_q_enu", "give either 'process_noise_q' (every axis) or 'process_noise_q_enu', not both");
  if (params.given("process_noise_q_enu")) return params.vec3("process_noise_q_enu");
  return Vec3::Constant(params.real("process_noise_q"));
}

Vec3 process_noise_q_jerk(const Params& params) {
  if (params.given("process_noise_q_jerk") && params.given("process_noise_q_jerk_enu"))
    throw params.error("process_noise_q_jerk_enu",
                       "give either 'process_noise_q_jerk' (every axis) or 'process_noise_q_jerk_enu', not both");
  const bool jerk = params.given("process_noise_q_jerk") || params.given("process_noise_q_jerk_enu");
  const bool accel = params.given("process_noise_q") || params.given("process_noise_q_enu");
  if (jerk && accel)
    throw params.error(params.given("process_noise_q_jerk") ? "process_noise_q_jerk" : "process_noise_q_jerk_enu",
                       "is a second process-noise model: give white acceleration (process_noise_q*) or white jerk "
                       "(process_noise_q_jerk*), not both");
  if (params.given("process_noise_q_jerk_enu")) return params.vec3("process_noise_q_jerk_enu");
  return Vec3::Constant(params.real("process_noise_q_jerk"));
}

}  // namespace trackflow::sim
