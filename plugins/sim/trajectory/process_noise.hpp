// Purpose: the white-noise-acceleration (CV) and white-noise-jerk (CA) deviations added to a trajectory's truth, exactly discretised per sample.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>
#include <trackflow/rng.hpp>

#include <cstdint>

namespace trackflow::sim {

// Per ENU axis, a deviation [dp, dv] from the deterministic profile driven by white acceleration
// of spectral density q (m2/s3): the continuous white noise acceleration model of Bar-Shalom,
// Li & Kirubarajan 2001 §6.2.2. Over one period T it evolves exactly as
//   [dp, dv] <- [[1, T], [0, 1]] [dp, dv] + w,   w ~ N(0, q [[T³/3, T²/2], [T²/2, T]]),
// so a CV filter with the same q is the matched model whatever the sample rate.
class WhiteAccelerationNoise {
 public:
  WhiteAccelerationNoise(const Vec3& q, double period);

  // False when q is zero on every axis: then nothing is drawn and nothing is added.
  bool enabled() const { return enabled_; }
  // Start of a run: zero deviation (the first sample is the profile's), stream from `seed`.
  void reset(std::uint64_t seed);
  // Advances the deviation by one period: two standard normals per axis, east, north, up.
  void step();

  const Vec3& position() const { return dp_; }
  const Vec3& velocity() const { return dv_; }
  // Mean white acceleration over the last period, Δdv / T (zero before the first step).
  const Vec3& acceleration() const { return mean_accel_; }

 private:
  // Cholesky factor of q [[T³/3, T²/2], [T²/2, T]] per axis: [[l11, 0], [l21, l22]].
  Vec3 l11_, l21_, l22_;
  double period_;
  bool enabled_;
  Vec3 dp_ = Vec3::Zero(), dv_ = Vec3::Zero(), mean_accel_ = Vec3::Zero();
  Rng rng_;
};

// Per ENU axis, a deviation [dp, dv, da] driven by white jerk of spectral density q (m2/s5): the
// Wiener-process acceleration model (Bar-Shalom, Li & Kirubarajan 2001 §6.2.3; paper 000 eq 3.19).
// Over one period T it evolves exactly as
//   [dp, dv, da] <- [[1, T, T²/2], [0, 1, T], [0, 0, 1]] [dp, dv, da] + w,
//   w ~ N(0, q [[T⁵/20, T⁴/8, T³/6], [T⁴/8, T³/3, T²/2], [T³/6, T²/2, T]]),
// so a constant-acceleration filter (filter.ekf, filter.ukf: q_jerk) with the same q is the
// matched model on a profile of constant acceleration.
class WhiteJerkNoise {
 public:
  WhiteJerkNoise(const Vec3& q, double period);

  bool enabled() const { return enabled_; }
  void reset(std::uint64_t seed);
  // Advances the deviation by one period: three standard normals per axis, east, north, up.
  void step();

  const Vec3& position() const { return dp_; }
  const Vec3& velocity() const { return dv_; }
  const Vec3& acceleration() const { return da_; }  // a state of this model, continuous in time

 private:
  // Lower-triangular Cholesky factor of the per-period covariance for q = 1 (scaled per axis by √q).
  Eigen::Matrix3d chol_ = Eigen::Matrix3d::Zero();
  Vec3 scale_;
  double period_;
  bool enabled_;
  Vec3 dp_ = Vec3::Zero(), dv_ = Vec3::Zero(), da_ = Vec3::Zero();
  Rng rng_;
};

// The per-axis q from `process_noise_q` (every axis) or `process_noise_q_enu` (one per axis);
// giving both is refused.
Vec3 process_noise_q(const Params& params);
// The same for the white-jerk model: `process_noise_q_jerk` or `process_noise_q_jerk_enu`.
// Either model, not both: giving a white-acceleration and a white-jerk q is refused.
Vec3 process_noise_q_jerk(const Params& params);

}  // namespace trackflow::sim
