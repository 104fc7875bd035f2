// Purpose: the exact per-period draw of the white-noise-acceleration deviation and the reading of its q.
#include "process_noise.hpp"

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

Vec3 process_noise_q(const Params& params) {
  if (params.given("process_noise_q") && params.given("process_noise_q_enu"))
    throw params.error("process_noise_q_enu", "give either 'process_noise_q' (every axis) or 'process_noise_q_enu', not both");
  if (params.given("process_noise_q_enu")) return params.vec3("process_noise_q_enu");
  return Vec3::Constant(params.real("process_noise_q"));
}

}  // namespace trackflow::sim
