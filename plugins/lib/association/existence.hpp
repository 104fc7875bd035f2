// Purpose: a track's existence probability through one look (IPDA, JIPDA: Musicki & Evans) — its prediction, the existence-weighted event factors, the posterior, and the association probabilities conditioned on existence — for assoc.pda and assoc.jpda.
#pragma once

#include <cmath>
#include <span>

namespace trackflow::association {

// Markov chain one (Musicki, Evans & Stankovic 1994, "Integrated probabilistic data association",
// IEEE Trans. AC 39(6):1237-1241, eq. 7; Musicki & Evans 2004, "Joint integrated probabilistic
// data association: JIPDA", IEEE Trans. AES 40(3):1093-1099): a target that exists at one look
// still exists at the next with probability `survival`; none is born into a track.
inline double predicted_existence(double r, double survival) { return survival * r; }

// The event factors of a track with predicted existence r (JIPDA, eq. 14-16 of Musicki & Evans
// 2004): a miss weighs 1 - P_D P_G r (absent, or present and undetected), a detection r P_D g / lambda.
// In the log domain: log(1 - P_D P_G r) and log r (added to log(P_D g / lambda)).
inline double log_miss_factor(double r, double pd_pg) { return std::log1p(-pd_pg * r); }
inline double log_detection_factor(double r) { return std::log(r); }

// From the marginals of the existence-weighted events — beta[k] of each candidate, beta_none of
// none — to the posterior existence and the association probabilities given that the target
// exists (what the state update mixes):
//   r+ = sum_k beta_k + beta_none q,   q = (1 - P_D P_G) r / (1 - P_D P_G r),
// (the share of the "none" events in which the target exists, undetected), then beta_k / r+ and
// beta_none q / r+, which sum to 1. r = 0: r+ = 0 and the update is the prediction (none = 1).
inline double condition_on_existence(double r, double pd_pg, std::span<double> beta, double& beta_none) {
  const double q = r > 0.0 ? (1.0 - pd_pg) * r / (1.0 - pd_pg * r) : 0.0;
  double r_post = beta_none * q;
  for (double b : beta) r_post += b;
  if (!(r_post > 0.0)) {
    for (double& b : beta) b = 0.0;
    beta_none = 1.0;
    return 0.0;
  }
  for (double& b : beta) b /= r_post;
  beta_none = beta_none * q / r_post;
  return r_post > 1.0 ? 1.0 : r_post;
}

}  // namespace trackflow::association
