// Purpose: an exact Poisson(mean) draw from a trackflow Rng whose sequence is fixed by this code alone (clutter counts, births).
#pragma once

#include <trackflow/rng.hpp>

#include <cmath>
#include <cstdint>

namespace trackflow::simulation {

// Poisson(mean) from uniforms of `rng`: multiplication of uniforms (Knuth) below 30, above it the
// transformed rejection with squeeze of Hörmann 1993 (PTRS), so the draw is exact at any mean
// and its sequence fixed by this code alone (not by a standard library's distribution).
inline std::uint64_t poisson(Rng& rng, double mean) {
  if (!(mean > 0.0)) return 0;
  if (mean < 30.0) {
    const double limit = std::exp(-mean);
    std::uint64_t k = 0;
    double prod = rng.uniform();
    while (prod > limit) {
      ++k;
      prod *= rng.uniform();
    }
    return k;
  }
  const double slam = std::sqrt(mean), loglam = std::log(mean);
  const double b = 0.931 + 2.53 * slam, a = -0.059 + 0.02483 * b;
  const double invalpha = 1.1239 + 1.1328 / (b - 3.4), vr = 0.9277 - 3.6224 / (b - 2.0);
  for (;;) {
    const double u = rng.uniform() - 0.5, v = rng.uniform();
    const double us = 0.5 - std::fabs(u);
    const double k = std::floor((2.0 * a / us + b) * u + mean + 0.43);
    if (us >= 0.07 && v <= vr) return static_cast<std::uint64_t>(k);
    if (k < 0.0 || (us < 0.013 && v > us)) continue;
    int sign = 0;
    if (std::log(v) + std::log(invalpha) - std::log(a / (us * us) + b) <= -mean + k * loglam - ::lgamma_r(k + 1.0, &sign))
      return static_cast<std::uint64_t>(k);
  }
}

}  // namespace trackflow::simulation
