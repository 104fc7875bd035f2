// Purpose: how many joint association events a JPDA cluster has — a depth-first count that stops at a limit, a product upper bound, and the closed form sum_k C(n,k) C(m,k) k! of a fully ambiguous n x m cluster (all saturating).
#pragma once

#include "association/jpda_clusters.hpp"
#include "memory/grow.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace trackflow::association {

inline constexpr std::uint64_t kJpdaEventsSaturated = std::numeric_limits<std::uint64_t>::max();

// Joint events of a fully ambiguous cluster (n tracks, m detections, every pair gated): choose the
// k tracks that are detected, the k detections they take and the k! ways to match them,
//   E(n, m) = sum_{k=0}^{min(n,m)} C(n,k) C(m,k) k!
// (e.g. E(10, 10) = 234 662 231). Term by term, t_k = t_{k-1} (n-k+1)(m-k+1) / k, exact in 128-bit
// integers (t_k is an integer, so the product divides by k; t_{k-1} < 2^64 and the factors < 2^64
// keep the product below 2^128); saturates at kJpdaEventsSaturated instead of overflowing.
inline std::uint64_t full_cluster_events(std::uint64_t n, std::uint64_t m) {
  const std::uint64_t kmax = std::min(n, m);
  unsigned __int128 term = 1, sum = 1;
  const unsigned __int128 cap = kJpdaEventsSaturated;
  for (std::uint64_t k = 1; k <= kmax; ++k) {
    const unsigned __int128 a = n - k + 1, b = m - k + 1;
    // The sum is at least t_1 = n m >= (n-k+1)(m-k+1): a product beyond 2^64 means saturation, and
    // below it term * a * b stays below 2^128.
    if (a * b > cap) return kJpdaEventsSaturated;
    term = term * a * b / k;
    if (term > cap) return kJpdaEventsSaturated;
    sum += term;
    if (sum > cap) return kJpdaEventsSaturated;
  }
  return static_cast<std::uint64_t>(sum);
}

// An upper bound of the event count without enumeration: each track takes none or one of its
// gated detections, so events <= prod_t (1 + deg t) (equality when no two tracks share a
// detection). Saturating.
inline std::uint64_t jpda_events_upper_bound(const JpdaCluster& c) {
  std::uint64_t p = 1;
  for (int t = 0; t < c.size_tracks(); ++t) {
    const auto deg = static_cast<std::uint64_t>(c.track_begin[static_cast<std::size_t>(t) + 1] -
                                                c.track_begin[static_cast<std::size_t>(t)]);
    if (p > kJpdaEventsSaturated / (deg + 1)) return kJpdaEventsSaturated;
    p *= deg + 1;
  }
  return p;
}

// The number of joint events of a cluster, counted by the same depth-first walk as the exact
// enumeration (jpda_exact.hpp) but without weights: tracks in local order, each taking "none" or
// one gated detection no earlier track took. The last track's choices are counted at once (1 +
// its free detections) instead of visited. The walk stops as soon as the count exceeds `limit`
// and returns limit + 1: "more than limit", found after at most about limit x tracks steps,
// however many events there are. That is all marginals() needs to choose between the exact
// enumeration (at most max_events events) and belief propagation, and it costs no more than
// the enumeration it may save. Storage: members, nothing allocated once grown.
class JpdaEventCounter {
 public:
  std::uint64_t count(const JpdaCluster& c, std::uint64_t limit) {
    limit = std::min(limit, kJpdaEventsSaturated - 1);
    const int nt = c.size_tracks();
    if (nt == 0) return 1;  // the empty event
    memory::assign_grown(used_, c.detections.size(), char{0});
    memory::assign_grown(option_, static_cast<std::size_t>(nt), -1);
    std::uint64_t events = 0;
    int d = 0;
    option_[0] = -1;
    const auto det = [&](int t, int o) {  // local detection of option o >= 1 of track t
      return static_cast<std::size_t>(
          c.pairs[static_cast<std::size_t>(c.track_begin[static_cast<std::size_t>(t)] + o - 1)].detection);
    };
    while (true) {
      const auto t = static_cast<std::size_t>(d);
      const int deg = c.track_begin[t + 1] - c.track_begin[t];
      if (d == nt - 1) {
        std::uint64_t free = 1;
        for (int o = 1; o <= deg; ++o) free += used_[det(d, o)] ? 0 : 1;
        events += free;
        if (events > limit) return limit + 1;
        if (d == 0) break;
        --d;
        continue;
      }
      int o = option_[t];
      if (o > 0) used_[det(d, o)] = 0;
      ++o;
      while (o > 0 && o <= deg && used_[det(d, o)]) ++o;  // option 0 ("none") is always free
      if (o > deg) {
        if (d == 0) break;
        --d;
        continue;
      }
      option_[t] = o;
      if (o > 0) used_[det(d, o)] = 1;
      ++d;
      option_[static_cast<std::size_t>(d)] = -1;
    }
    return events;
  }

 private:
  std::vector<char> used_;
  std::vector<int> option_;
};

}  // namespace trackflow::association
