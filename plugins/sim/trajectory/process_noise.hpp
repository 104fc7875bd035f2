// Purpose: the continuous white-noise-acceleration deviation added to a trajectory's truth, exactly discretised per sample.
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

// The per-axis q from `process_noise_q` (every axis) or `process_noise_q_enu` (one per axis);
// giving both is refused.
Vec3 process_noise_q(const Params& params);

}  // namespace trackflow::sim
