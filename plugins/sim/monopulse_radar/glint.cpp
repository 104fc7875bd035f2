// Purpose: the glint mixture's variances and its DAR(1) renewal draws.
#include "glint.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace trackflow::sim {

MixtureVariances mixture_variances(const GlintSettings& s) {
  const double g = s.sigma * s.sigma / ((1.0 - s.laplace_weight) + s.laplace_weight * s.variance_ratio);
  return {g, s.variance_ratio * g};
}

GlintProcess::GlintProcess(GlintSettings s) : s_(s) {
  const MixtureVariances v = mixture_variances(s_);
  sd_gauss_ = std::sqrt(v.gaussian);
  sd_laplace_ = std::sqrt(v.laplacian);
  axis_scale_ = s_.per_plane ? std::sqrt(2.0) : 1.0;
}

void GlintProcess::renew(double fade_uniform, Rng& rng) {
  laplacian_ = rng.uniform() < s_.laplace_weight;
  const double own = rng.uniform();
  const double n = rng.normal();
  const double alpha = 2.0 * std::numbers::pi * rng.uniform();
  if (laplacian_) {
    const double u = std::isnan(fade_uniform) ? own : fade_uniform;
    // U in (0, 1]; U = 1 (no fade at all) gives E = 0: a zero Laplacian draw, which has probability 0
    // in exact arithmetic; U = 0 cannot occur for x > 0, and is floored at the smallest double.
    const double e = -std::log(std::max(u, 1e-300));
    g_ = sd_laplace_ * std::sqrt(e) * n;
  } else {
    g_ = sd_gauss_ * n;
  }
  az_ = axis_scale_ * g_ * std::cos(alpha);
  el_ = axis_scale_ * g_ * std::sin(alpha);
}

}  // namespace trackflow::sim
