// Purpose: exact JPDA marginal association probabilities of one cluster by depth-first enumeration of its joint association events, counting the events visited.
#pragma once

#include "association/jpda_clusters.hpp"
#include "association/jpda_weights.hpp"
#include "memory/grow.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace trackflow::association {

// Parametric JPDA (Fortmann, Bar-Shalom & Scheffe 1983; Bar-Shalom, Willett & Tian 2011, ch. 7/8):
// a joint event theta gives each track one gated detection or none, each detection to at most one
// track; its weight is
//   w(theta) = prod_i ( theta(i) = none ? w_i0 : l_i,theta(i) ),
//   w_i0 = 1 - P_D P_G,  l_ij = P_D g_ij / lambda,
// and the marginals are
//   beta_ij = sum_{theta: theta(i) = j} w(theta) / sum_theta w(theta),  beta_i0 likewise for none.
//
// Enumeration: a depth-first walk over the tracks in local order, track d trying "none" and then
// each of its gated detections (ascending) that no earlier track holds. Rather than adding each
// leaf's weight to all n of its marginals (n work per event), the walk keeps for every depth d
//   P_d = the product of the factors chosen at depths < d, and
//   S_d = the sum over the completions of depths d..n-1 compatible with the detections held,
// and when option o of track d has been explored, beta(d, o) += P_d f(d, o) S_{d+1} and
// S_d += f(d, o) S_{d+1}: each explored node costs O(1), and sum_theta w(theta) = S_0. The last
// track's options are leaves: each is one event (`events` counts them; equal to
// JpdaEventCounter::count for every cluster).
//
// Numbers: per-track scaled weights (jpda_weights.hpp), so every factor is <= 1 and each track's
// largest is 1. The walk runs in double; a product of the scaled factors can still underflow
// when tracks are forced into weights far below their best (e.g. four tracks whose only
// detection is shared, each missing at 1e-130 of taking it: every event weighs <= 1e-390). An
// event below 1e-308 is negligible next to a total of at least 1e-250 (1e-58 relative, and there
// are far fewer than 1e58 events), so a total >= 1e-250 is accepted; below it, the walk is redone
// in long double (x86-64: range 1e±4932), which only such extreme clusters pay for (the double
// walk is 2-3 x faster: ~8 ns per event on 7 x 7 and 8 x 8 full clusters, g++ 12 -O2, against
// 15-26 ns in long double). The marginals' sums are compensated (see Sum below).
//
// Cost: O(explored nodes) <= O(events x tracks), usually about the number of events.
// Storage: members, nothing allocated once grown.
class JpdaExact {
 public:
  // Returns the number of joint events visited (0, and NaN betas, only if even long double
  // underflows: weight ratios within tracks beyond about 1e4900). Afterwards miss_beta()[t] is
  // the beta of local track t taking no detection and pair_beta()[k] that of the cluster's pair k.
  std::uint64_t run(const JpdaCluster& c, std::span<const double> log_miss) {
    beta_miss_.resize(c.tracks.size());
    beta_pair_.resize(c.pairs.size());
    const std::uint64_t events = double_.run(c, log_miss, beta_miss_, beta_pair_, 1e-250);
    extended_ = events == 0;
    if (!extended_) return events;
    const std::uint64_t again = extended_walk_.run(c, log_miss, beta_miss_, beta_pair_, 0.0L);
    if (again == 0) {  // every event below long double's range: no answer
      std::fill(beta_miss_.begin(), beta_miss_.end(), std::numeric_limits<double>::quiet_NaN());
      std::fill(beta_pair_.begin(), beta_pair_.end(), std::numeric_limits<double>::quiet_NaN());
    }
    return again;
  }

  std::span<const double> miss_beta() const { return beta_miss_; }
  std::span<const double> pair_beta() const { return beta_pair_; }
  // Whether the last run needed the long double walk.
  bool extended() const { return extended_; }

 private:
  template <class Real>
  class Walk {
   public:
    // The betas into miss_out / pair_out and the events visited; 0 (nothing written) when the
    // total is below min_total.
    std::uint64_t run(const JpdaCluster& c, std::span<const double> log_miss, std::span<double> miss_out,
                      std::span<double> pair_out, Real min_total) {
      weights_.compute(c, log_miss, Real{0});
      const std::span<const Real> miss = weights_.miss(), pair = weights_.pair();
      const int nt = c.size_tracks();
      if (nt == 0) return 1;  // the empty event
      memory::assign_grown(acc_miss_, static_cast<std::size_t>(nt), Sum{});
      memory::assign_grown(acc_pair_, c.pairs.size(), Sum{});
      memory::assign_grown(used_, c.detections.size(), char{0});
      memory::assign_grown(option_, static_cast<std::size_t>(nt), -1);
      memory::assign_grown(prefix_, static_cast<std::size_t>(nt) + 1, Real{0});
      memory::assign_grown(sub_, static_cast<std::size_t>(nt) + 1, Real{0});
      const auto begin = [&](int t) { return c.track_begin[static_cast<std::size_t>(t)]; };
      // Option o of track t: 0 = none, o >= 1 = the track's pair begin(t) + o - 1.
      const auto factor = [&](int t, int o) {
        return o == 0 ? miss[static_cast<std::size_t>(t)] : pair[static_cast<std::size_t>(begin(t) + o - 1)];
      };
      const auto accum = [&](int t, int o) -> Sum& {
        return o == 0 ? acc_miss_[static_cast<std::size_t>(t)] : acc_pair_[static_cast<std::size_t>(begin(t) + o - 1)];
      };
      const auto det = [&](int t, int o) {
        return static_cast<std::size_t>(c.pairs[static_cast<std::size_t>(begin(t) + o - 1)].detection);
      };

      std::uint64_t events = 0;
      int d = 0;
      prefix_[0] = 1;
      sub_[0] = 0;
      option_[0] = -1;
      while (true) {
        const auto t = static_cast<std::size_t>(d);
        const int deg = begin(d + 1) - begin(d);
        if (d == nt - 1) {  // leaves: every free option of the last track completes one event
          for (int o = 0; o <= deg; ++o) {
            if (o > 0 && used_[det(d, o)]) continue;
            const Real f = factor(d, o);
            accum(d, o).add(prefix_[t] * f);
            sub_[t] += f;
            ++events;
          }
          if (d == 0) break;
          --d;
          continue;
        }
        int o = option_[t];
        if (o >= 0) {  // option o explored: its subtree's sum is S_{d+1}
          const Real fs = factor(d, o) * sub_[t + 1];
          accum(d, o).add(prefix_[t] * fs);
          sub_[t] += fs;
          if (o > 0) used_[det(d, o)] = 0;
        }
        ++o;
        while (o > 0 && o <= deg && used_[det(d, o)]) ++o;
        if (o > deg) {
          if (d == 0) break;
          --d;
          continue;
        }
        option_[t] = o;
        if (o > 0) used_[det(d, o)] = 1;
        prefix_[t + 1] = prefix_[t] * factor(d, o);
        sub_[t + 1] = 0;
        option_[t + 1] = -1;
        ++d;
      }
      const Real total = sub_[0];
      if (!(total >= min_total) || !(total > 0)) return 0;
      for (std::size_t k = 0; k < static_cast<std::size_t>(nt); ++k)
        miss_out[k] = static_cast<double>(acc_miss_[k].value() / total);
      for (std::size_t k = 0; k < c.pairs.size(); ++k) pair_out[k] = static_cast<double>(acc_pair_[k].value() / total);
      return events;
    }

   private:
    // A marginal's sum takes one term per explored node of its depth (up to ~1e5 on an 8 x 8
    // cluster): compensated (Neumaier's variant of Kahan summation), so its rounding error stays
    // at a few ulps instead of growing with the count.
    struct Sum {
      Real s = 0, c = 0;
      void add(Real x) {
        const Real t = s + x;
        c += std::fabs(s) >= std::fabs(x) ? (s - t) + x : (x - t) + s;
        s = t;
      }
      Real value() const { return s + c; }
    };
    JpdaScaledWeights<Real> weights_;
    std::vector<Sum> acc_miss_, acc_pair_;
    std::vector<Real> prefix_, sub_;
    std::vector<char> used_;
    std::vector<int> option_;
  };

  Walk<double> double_;
  Walk<long double> extended_walk_;
  bool extended_ = false;
  std::vector<double> beta_miss_, beta_pair_;
};

}  // namespace trackflow::association
