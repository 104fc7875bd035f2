// Purpose: one JPDA cluster's weights per track scaled by that track's largest (miss weight w_i0 and likelihood ratios l_ij from their logs), so that no weight under- or overflows and every beta is unchanged.
#pragma once

#include "association/jpda_clusters.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <vector>

namespace trackflow::association {

// r_i0 = exp(log w_i0 - M_i), r_ij = exp(log l_ij - M_i), M_i = max(log w_i0, max_j log l_ij).
//
// Why the betas do not change: a joint event theta has exactly one factor per track (w_i0 or
// l_i,theta(i)), so dividing track i's weights by e^{M_i} divides every event's weight by the same
// e^{M_i}, which cancels between the numerator and the denominator of each beta (the normalised
// joint event probabilities of parametric JPDA: Bar-Shalom, Willett & Tian 2011, ch. 7/8;
// Fortmann, Bar-Shalom & Scheffe 1983). Each track's largest
// weight becomes 1, so likelihoods of 1e-300 or 1e300 become ordinary numbers; only a ratio
// between two weights of one track beyond the range of Real can underflow (to 0 after a floor, see
// below).
//
// Real: double (belief propagation; the exact enumeration first), long double (the exact
// enumeration when a product of scaled factors underflows double: jpda_exact.hpp). `floor` (>= 0)
// bounds every scaled weight from below (LBP: 1e-300, so that its message denominators stay
// positive; exact: 0).
//
// Inputs: log_miss indexed by scan track (size above the cluster's largest track), every log
// finite (std::invalid_argument otherwise).
template <class Real>
class JpdaScaledWeights {
 public:
  void compute(const JpdaCluster& c, std::span<const double> log_miss, Real floor) {
    const std::size_t nt = c.tracks.size();
    if (nt > 0 && static_cast<std::size_t>(c.tracks.back()) >= log_miss.size())
      throw std::invalid_argument("jpda: fewer miss weights than tracks");
    miss_.resize(nt);
    pair_.resize(c.pairs.size());
    for (std::size_t t = 0; t < nt; ++t) {
      const double lm = log_miss[static_cast<std::size_t>(c.tracks[t])];
      if (!std::isfinite(lm)) throw std::invalid_argument("jpda: a miss weight's log must be finite");
      double top = lm;
      const auto b = static_cast<std::size_t>(c.track_begin[t]), e = static_cast<std::size_t>(c.track_begin[t + 1]);
      for (std::size_t k = b; k < e; ++k) {
        if (!std::isfinite(c.pairs[k].log_weight))
          throw std::invalid_argument("jpda: a pair's log weight must be finite");
        top = std::max(top, c.pairs[k].log_weight);
      }
      miss_[t] = std::max(floor, std::exp(static_cast<Real>(lm) - static_cast<Real>(top)));
      for (std::size_t k = b; k < e; ++k)
        pair_[k] = std::max(floor, std::exp(static_cast<Real>(c.pairs[k].log_weight) - static_cast<Real>(top)));
    }
  }

  // Scaled miss weight of local track t; scaled weight of the cluster's pair k.
  std::span<const Real> miss() const { return miss_; }
  std::span<const Real> pair() const { return pair_; }

 private:
  std::vector<Real> miss_, pair_;
};

}  // namespace trackflow::association
