// Purpose: approximate JPDA marginal association probabilities of one cluster by loopy belief propagation between track and detection nodes (Williams & Lau 2014), iterated to a message tolerance.
#pragma once

#include "association/jpda_clusters.hpp"
#include "association/jpda_weights.hpp"
#include "memory/grow.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace trackflow::association {

struct LbpOptions {
  double tolerance = 1e-9;     // stop when the largest relative change of a message is below this
  int max_iterations = 10000;  // and stop anyway after this many (then converged = false)
};

struct LbpResult {
  int iterations = 0;      // message-passing rounds done (each: all track->detection, then all detection->track)
  bool converged = false;  // the last round's largest relative message change < tolerance
  double change = 0.0;     // that change
};

// J. L. Williams and R. A. Lau, "Approximate evaluation of marginal association probabilities with
// belief propagation", IEEE Trans. AES 50(4):2942-2959, 2014 (arXiv:1209.6299).
//
// Model (their graphical-model formulation): the JPDA event distribution written over track
// variables a_i (0 = none, j = detection j) and detection variables b_j (0 = clutter, i = track i),
//   p(a, b) ∝ prod_i psi_i(a_i) prod_{(i,j) gated} psi_ij(a_i, b_j),
// psi_i(j) = l_ij / w_i0 (their normalisation psi_i(0) = 1; a detection's clutter weight is 1
// because l_ij is already a ratio to the clutter density), psi_ij = 0 when exactly one of a_i = j,
// b_j = i holds (consistency), else 1. The factor graph is the bipartite gating graph.
//
// Messages (their simplified BP: belief propagation on this graph reduces to one number per edge and
// direction), a synchronous round being
//   mu_{i->j} = psi_i(j) / ( 1 + sum_{j' != j} psi_i(j') nu_{j'->i} )     (track -> detection)
//   nu_{j->i} = 1 / ( 1 + sum_{i' != i} mu_{i'->j} )                       (detection -> track)
// from nu = 1, and the beliefs
//   beta_ij ≈ psi_i(j) nu_{j->i} / ( 1 + sum_j' psi_i(j') nu_{j'->i} ),   beta_i0 ≈ 1 / (same).
// They prove that the iteration converges and bound the rounds it needs. On a gating graph that
// is a tree, BP is exact (as on any tree); a single track gives the PDA closed form.
//
// Here:
//   - psi_i(j) is replaced by the per-track scaled weights r_ij and 1 by r_i0 (jpda_weights.hpp):
//     mu_{i->j} = r_ij / (r_i0 + sum_{j' != j} r_ij' nu_{j'->i}) is unchanged by the scaling, and
//     r <= 1 keeps every number in range. r is floored at 1e-300, so the denominators stay > 0
//     (only ratios beyond 1e300 within one track are touched; exact enumeration has no floor).
//   - the leave-one-out sums are formed from prefix and suffix sums, not as "total minus own
//     term": no cancellation when one term dominates (which random weights over many orders of
//     magnitude make common), O(degree) per node.
//   - convergence test: the largest relative change of a nu over a round, |nu' - nu| / max(nu',
//     nu), i.e. about the change of log nu (the measure their convergence bound is stated in, as in
//     Stone Soup's JPDAwithLBP); each belief then moves by about that relative amount, however
//     small nu is. mu is a function of nu, so it has settled too.
//
// Cost: O(pairs) per round. Storage: members, nothing allocated once grown.
class JpdaBeliefPropagation {
 public:
  LbpResult run(const JpdaCluster& c, std::span<const double> log_miss, LbpOptions options = {}) {
    weights_.compute(c, log_miss, 1e-300);
    const std::span<const double> r0 = weights_.miss(), r = weights_.pair();
    const int nt = c.size_tracks(), nd = c.size_detections();
    const std::size_t np = c.pairs.size();
    beta_miss_.resize(static_cast<std::size_t>(nt));
    beta_pair_.resize(np);
    memory::assign_grown(nu_, np, 1.0);
    memory::assign_grown(mu_, np, 0.0);
    tmp_.resize(np);
    // The pairs of each detection (tracks ascending: a stable counting sort of the track-ordered
    // pairs by detection).
    memory::assign_grown(det_begin_, static_cast<std::size_t>(nd) + 1, 0);
    for (const JpdaClusterPair& p : c.pairs) ++det_begin_[static_cast<std::size_t>(p.detection) + 1];
    for (int j = 0; j < nd; ++j) det_begin_[static_cast<std::size_t>(j) + 1] += det_begin_[static_cast<std::size_t>(j)];
    det_pairs_.resize(np);
    memory::assign_grown(fill_, static_cast<std::size_t>(nd), 0);
    for (std::size_t k = 0; k < np; ++k) {
      const auto j = static_cast<std::size_t>(c.pairs[k].detection);
      det_pairs_[static_cast<std::size_t>(det_begin_[j] + fill_[j]++)] = static_cast<int>(k);
    }

    LbpResult result;
    result.converged = np == 0;
    while (!result.converged && result.iterations < options.max_iterations) {
      ++result.iterations;
      // Track -> detection.
      for (int t = 0; t < nt; ++t) {
        const auto b = static_cast<std::size_t>(c.track_begin[static_cast<std::size_t>(t)]);
        const auto e = static_cast<std::size_t>(c.track_begin[static_cast<std::size_t>(t) + 1]);
        double pre = 0.0;
        for (std::size_t k = b; k < e; ++k) {
          tmp_[k] = pre;
          pre += r[k] * nu_[k];
        }
        double suf = 0.0;
        for (std::size_t k = e; k-- > b;) {
          mu_[k] = r[k] / (r0[static_cast<std::size_t>(t)] + (tmp_[k] + suf));
          suf += r[k] * nu_[k];
        }
      }
      // Detection -> track, and the round's largest relative change.
      double change = 0.0;
      for (int j = 0; j < nd; ++j) {
        const auto b = static_cast<std::size_t>(det_begin_[static_cast<std::size_t>(j)]);
        const auto e = static_cast<std::size_t>(det_begin_[static_cast<std::size_t>(j) + 1]);
        double pre = 0.0;
        for (std::size_t q = b; q < e; ++q) {
          tmp_[q] = pre;
          pre += mu_[static_cast<std::size_t>(det_pairs_[q])];
        }
        double suf = 0.0;
        for (std::size_t q = e; q-- > b;) {
          const auto k = static_cast<std::size_t>(det_pairs_[q]);
          const double next = 1.0 / (1.0 + (tmp_[q] + suf));
          change = std::max(change, std::fabs(next - nu_[k]) / std::max(next, nu_[k]));
          suf += mu_[k];
          nu_[k] = next;
        }
      }
      result.change = change;
      result.converged = change < options.tolerance;
    }
    // Beliefs.
    for (int t = 0; t < nt; ++t) {
      const auto b = static_cast<std::size_t>(c.track_begin[static_cast<std::size_t>(t)]);
      const auto e = static_cast<std::size_t>(c.track_begin[static_cast<std::size_t>(t) + 1]);
      double z = r0[static_cast<std::size_t>(t)];
      for (std::size_t k = b; k < e; ++k) z += r[k] * nu_[k];
      beta_miss_[static_cast<std::size_t>(t)] = r0[static_cast<std::size_t>(t)] / z;
      for (std::size_t k = b; k < e; ++k) beta_pair_[k] = r[k] * nu_[k] / z;
    }
    return result;
  }

  std::span<const double> miss_beta() const { return beta_miss_; }
  std::span<const double> pair_beta() const { return beta_pair_; }

 private:
  JpdaScaledWeights<double> weights_;
  std::vector<double> nu_, mu_, tmp_;
  std::vector<int> det_begin_, det_pairs_, fill_;
  std::vector<double> beta_miss_, beta_pair_;
};

}  // namespace trackflow::association
