// Purpose: JPDA marginal association probabilities of one cluster — exact enumeration when its joint events are few enough, loopy belief propagation otherwise — with a report of which was used.
#pragma once

#include "association/jpda_clusters.hpp"
#include "association/jpda_events.hpp"
#include "association/jpda_exact.hpp"
#include "association/jpda_lbp.hpp"

#include <cstdint>
#include <span>

namespace trackflow::association {

enum class JpdaMethod { exact, belief_propagation };

struct JpdaReport {
  JpdaMethod method = JpdaMethod::exact;
  // exact: the joint events enumerated. belief propagation: what the count found, max_events + 1
  // meaning "more than max_events" (the count stops there); 0 when called directly.
  std::uint64_t events = 0;
  LbpResult lbp;  // belief propagation only
};

// Usage, per scan: JpdaClusters::build over the gated pairs (log l_ij), then for each cluster c
// marginals(clusters[c], log_miss, max_events); pair_beta()[k] belongs to the cluster's pair k
// (its scan pair: clusters[c].pairs[k].source), miss_beta()[t] to its track clusters[c].tracks[t].
// Each track's betas sum to 1. The views are valid until the next call.
//
// Choice: exact when the cluster has at most max_events joint events. Deciding it does not
// enumerate a large cluster: first the bound prod (1 + deg) (jpda_events.hpp) — at most
// max_events: exact at once — then the depth-first count that stops at max_events + 1.
// Belief propagation is exact on a tree-shaped cluster too, but the count decides alone, so that
// the method depends only on the event count.
//
// Storage: members, nothing allocated once grown.
class JpdaMarginals {
 public:
  JpdaReport exact(const JpdaCluster& c, std::span<const double> log_miss) {
    JpdaReport report;
    report.method = JpdaMethod::exact;
    report.events = exact_.run(c, log_miss);
    miss_ = exact_.miss_beta();
    pair_ = exact_.pair_beta();
    return report;
  }

  JpdaReport loopy_belief_propagation(const JpdaCluster& c, std::span<const double> log_miss, LbpOptions options = {}) {
    JpdaReport report;
    report.method = JpdaMethod::belief_propagation;
    report.lbp = lbp_.run(c, log_miss, options);
    miss_ = lbp_.miss_beta();
    pair_ = lbp_.pair_beta();
    return report;
  }

  JpdaReport marginals(const JpdaCluster& c, std::span<const double> log_miss, std::uint64_t max_events,
                       LbpOptions options = {}) {
    if (jpda_events_upper_bound(c) <= max_events) return exact(c, log_miss);
    const std::uint64_t events = counter_.count(c, max_events);
    if (events <= max_events) return exact(c, log_miss);
    JpdaReport report = loopy_belief_propagation(c, log_miss, options);
    report.events = events;
    return report;
  }

  std::span<const double> miss_beta() const { return miss_; }
  std::span<const double> pair_beta() const { return pair_; }

 private:
  JpdaExact exact_;
  JpdaBeliefPropagation lbp_;
  JpdaEventCounter counter_;
  std::span<const double> miss_, pair_;
};

}  // namespace trackflow::association
