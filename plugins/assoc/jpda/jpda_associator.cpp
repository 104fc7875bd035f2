// Purpose: assoc.jpda — joint probabilistic data association: per cluster of tracks that share gated detections, the marginal probability that each detection is each track's over all joint events (exact enumeration up to max_events, loopy belief propagation above), optionally with each track's existence (JIPDA), for a combined update through each track's estimator.
#include "assignment/k_best_assignment.hpp"
#include "association/assumed_sensor.hpp"
#include "association/existence.hpp"
#include "association/gated_pairs.hpp"
#include "association/probabilistic_params.hpp"
#include "association/jpda_clusters.hpp"
#include "association/jpda_marginals.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow {
namespace {

struct JpdaSettings {
  double gate_probability = 0.99;
  association::AssumedSensor sensor;
  double initiation_threshold = 0.0;
  double survival = 0.0;  // > 0: JIPDA
  std::uint64_t max_events = 10000;
  enum class Approximation { BeliefPropagation, KBest } approximation = Approximation::BeliefPropagation;
  association::LbpOptions lbp;
  int k_best = 100;
};

// k-best JPDA (the marginals from the k most likely joint events only; Murty's ranking, as MATLAB's
// trackerJPDA "k-best" and Stone Soup's k-best JPDA): a cluster's joint events are the assignments
// of its n x (m + n) matrix — track t to detection d at cost -log l_td (gated pairs, else +inf), or
// to its own miss column at -log w_t0 (the other tracks' miss columns +inf) — so the k cheapest
// assignments (KBestAssignment, plugins/lib/assignment) are the k heaviest events, weight
// exp(-(cost - least cost)). With k at least the cluster's event count this is exact JPDA.
class KBestMarginals {
 public:
  // Fills pair_beta (the cluster's pairs' order) and miss_beta (its tracks' order).
  void run(const association::JpdaCluster& c, std::span<const double> log_miss, int k) {
    const int n = c.size_tracks(), m = c.size_detections(), cols = m + n;
    cost_.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(cols), std::numeric_limits<double>::infinity());
    column_pair_.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(cols), -1);
    for (std::size_t k2 = 0; k2 < c.pairs.size(); ++k2) {
      const association::JpdaClusterPair& p = c.pairs[k2];
      const std::size_t at = static_cast<std::size_t>(p.track) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(p.detection);
      cost_[at] = -p.log_weight;
      column_pair_[at] = static_cast<int>(k2);
    }
    for (int t = 0; t < n; ++t)
      cost_[static_cast<std::size_t>(t) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m + t)] =
          -log_miss[static_cast<std::size_t>(c.tracks[static_cast<std::size_t>(t)])];
    const std::span<const assignment::RankedAssignment> best = kbest_.solve(cost_, n, cols, k);
    pair_.assign(c.pairs.size(), 0.0);
    miss_.assign(static_cast<std::size_t>(n), 0.0);
    events_ = best.size();
    if (best.empty()) return;  // cannot happen: every track has its miss column
    const double least = best.front().total_cost;
    double total = 0.0;
    for (const assignment::RankedAssignment& a : best) {
      const double w = std::exp(least - a.total_cost);
      total += w;
      for (int t = 0; t < n; ++t) {
        const int col = a.column_for_row[static_cast<std::size_t>(t)];
        if (col >= m) {
          miss_[static_cast<std::size_t>(t)] += w;
        } else {
          pair_[static_cast<std::size_t>(column_pair_[static_cast<std::size_t>(t) * static_cast<std::size_t>(cols) +
                                                      static_cast<std::size_t>(col)])] += w;
        }
      }
    }
    for (double& b : pair_) b /= total;
    for (double& b : miss_) b /= total;
  }
  std::span<const double> pair_beta() const { return pair_; }
  std::span<const double> miss_beta() const { return miss_; }
  std::size_t events() const { return events_; }

 private:
  assignment::KBestAssignment kbest_;
  std::vector<double> cost_, pair_, miss_;
  std::vector<int> column_pair_;
  std::size_t events_ = 0;
};

// Parametric JPDA (T. E. Fortmann, Y. Bar-Shalom and M. Scheffe, "Sonar tracking of multiple targets
// using joint probabilistic data association", IEEE J. Oceanic Eng. 8(3):173-184, 1983;
// Bar-Shalom, Willett & Tian 2011, ch. 8): a joint event gives each track one gated detection or
// none, each detection to at most one track, and weighs
//   prod_i (track i missed ? 1 - P_D P_G : P_D N(z_j; z^_i, S_i) / lambda);
// beta_ij is the weight of the events in which track i takes detection j over the weight of all.
// The events factor over clusters (association/jpda_clusters.hpp), each computed on its own
// (association/jpda_marginals.hpp): exactly when it has at most max_events events, else by loopy
// belief propagation (Williams & Lau 2014). JIPDA (D. Musicki and R. Evans, "Joint integrated
// probabilistic data association: JIPDA", IEEE Trans. AES 40(3):1093-1099, 2004): with a survival
// probability, each track's factors carry its predicted existence r (association/existence.hpp) and
// the answer is conditioned on existence, the posterior existence published with it.
class JpdaAssociator final : public Associator {
 public:
  explicit JpdaAssociator(JpdaSettings s) : s_(std::move(s)), gated_(s_.gate_probability) {}

  bool probabilistic() const override { return true; }
  bool keeps_existence() const override { return s_.survival > 0.0; }
  void associate(std::span<const TrackView>, const Scan&, std::span<int>) override {
    throw std::logic_error("assoc.jpda gives association probabilities (associate_probabilities)");
  }

  void associate_probabilities(std::span<const TrackView> tracks, const Scan& scan, AssociationProbabilities& out) override {
    out.initiation_threshold = s_.initiation_threshold;
    const int n = static_cast<int>(tracks.size()), m = static_cast<int>(scan.detections.size());
    const double pd = s_.sensor.detection_probability(scan), pd_pg = pd * s_.gate_probability;
    const double log_ratio = m == 0 ? 0.0 : std::log(pd) - std::log(s_.sensor.clutter_density(scan));
    existence_.assign(static_cast<std::size_t>(n), 1.0);
    log_miss_.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      double& r = existence_[static_cast<std::size_t>(i)];
      if (keeps_existence()) r = association::predicted_existence(existing(tracks[static_cast<size_t>(i)]), s_.survival);
      log_miss_[static_cast<std::size_t>(i)] = association::log_miss_factor(r, pd_pg);
    }
    // Gated pairs, grouped by track (gated_pairs.hpp); a track whose existence is 0 takes none.
    pairs_.clear();
    if (m > 0)
      for (const association::GatedPair& g : gated_.find(tracks, scan)) {
        const double r = existence_[static_cast<std::size_t>(g.track)];
        if (r > 0.0) pairs_.push_back({g.track, g.detection, association::log_detection_factor(r) + log_ratio + g.log_likelihood});
      }
    clusters_.build(n, m, pairs_);
    pair_beta_.resize(pairs_.size());
    none_.resize(static_cast<std::size_t>(n));
    for (int c = 0; c < clusters_.size(); ++c) {
      const association::JpdaCluster& cl = clusters_[c];
      if (cl.pairs.empty()) {  // a lone track that gates nothing: it missed
        for (int t : cl.tracks) none_[static_cast<std::size_t>(t)] = 1.0;
        continue;
      }
      std::span<const double> miss, pair;
      if (s_.approximation == JpdaSettings::Approximation::KBest &&
          association::jpda_events_upper_bound(cl) > s_.max_events && counter_.count(cl, s_.max_events) > s_.max_events) {
        kbest_.run(cl, log_miss_, s_.k_best);
        ++out.approximate_clusters;
        miss = kbest_.miss_beta();
        pair = kbest_.pair_beta();
      } else {
        const association::JpdaReport report = marginals_.marginals(cl, log_miss_, s_.max_events, s_.lbp);
        if (report.method == association::JpdaMethod::exact) {
          ++out.exact_clusters;
        } else {
          ++out.approximate_clusters;
          if (!report.lbp.converged) ++out.unconverged_clusters;
        }
        miss = marginals_.miss_beta();
        pair = marginals_.pair_beta();
      }
      for (std::size_t t = 0; t < cl.tracks.size(); ++t) none_[static_cast<std::size_t>(cl.tracks[t])] = miss[t];
      for (std::size_t k = 0; k < cl.pairs.size(); ++k) pair_beta_[static_cast<std::size_t>(cl.pairs[k].source)] = pair[k];
    }
    // Per track, in track order (pairs_ is grouped by track ascending).
    std::size_t b = 0;
    for (int i = 0; i < n; ++i) {
      std::size_t e = b;
      while (e < pairs_.size() && pairs_[e].track == i) ++e;
      double none = none_[static_cast<std::size_t>(i)];
      if (keeps_existence()) {
        const std::span<double> beta(pair_beta_.data() + b, e - b);
        out.set_existence(i, association::condition_on_existence(existence_[static_cast<std::size_t>(i)], pd_pg, beta, none));
      }
      for (std::size_t k = b; k < e; ++k) out.add(i, pairs_[k].detection, pair_beta_[k]);
      out.set_none(i, none);
      b = e;
    }
  }

 private:
  // A track started without an existence (init.m_of_n, init.score) is taken as a target: r = 1.
  static double existing(const TrackView& v) { return std::isnan(v.existence) ? 1.0 : v.existence; }

  JpdaSettings s_;
  association::GatedPairs gated_;
  association::JpdaClusters clusters_;
  association::JpdaMarginals marginals_;
  association::JpdaEventCounter counter_;
  KBestMarginals kbest_;
  std::vector<association::JpdaPair> pairs_;
  std::vector<double> existence_, log_miss_, pair_beta_, none_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  JpdaSettings s;
  s.gate_probability = p.real("gate_probability");
  s.sensor = association::AssumedSensor(p, "assoc.jpda (node '" + p.node() + "')");
  s.initiation_threshold = p.real("initiation_threshold");
  s.survival = p.real_or("survival_probability", 0.0);
  s.max_events = static_cast<std::uint64_t>(p.integer("max_events"));
  s.lbp.tolerance = p.real("lbp_tolerance");
  s.lbp.max_iterations = static_cast<int>(p.integer("lbp_max_iterations"));
  s.approximation = p.choice<JpdaSettings::Approximation>("approximation");
  s.k_best = static_cast<int>(p.integer("k_best"));
  if (s.approximation != JpdaSettings::Approximation::KBest && p.given("k_best"))
    throw p.error("k_best", "is the number of joint events of approximation: k_best");
  return std::make_unique<JpdaAssociator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "assoc.jpda";
  d.kind = ComponentKind::Associator;
  d.summary = "Joint probabilistic data association: marginal association probabilities over the joint events of each "
              "cluster (exact up to max_events, loopy belief propagation above), optionally with existence (JIPDA)";
  d.doc =
      "A joint event gives each track one gated detection or none, each detection to at most one track, and weighs "
      "prod_i (missed ? 1 - P_D P_G : P_D N(z_j; z^_i, S_i) / lambda) (Fortmann, Bar-Shalom & Scheffe 1983; Bar-Shalom, "
      "Willett & Tian 2011, ch. 8); beta_ij = the weight of the events in which track i takes detection j over the "
      "weight of all, beta_i0 likewise for none. The events factor over clusters (tracks joined by shared gated "
      "detections), each computed on its own: by exact enumeration when it has at most max_events joint events "
      "(sum_k C(n,k) C(m,k) k! for n tracks fully competing for m detections), else by loopy belief propagation "
      "(Williams & Lau 2014; close to exact on average, up to ~0.3 off on one beta where two tracks compete hard for "
      "two detections) or, with approximation: k_best, from the k most likely joint events (Murty's k best assignments "
      "of the cluster's matrix of -log l and -log(1 - P_D P_G); exact when k reaches the event count), the choice "
      "counted per scan in the tracker's summary. The tracker updates each track with its "
      "candidates at once (the combined update, as for assoc.pda). With survival_probability p_s: JIPDA (Musicki & "
      "Evans 2004) - each track's existence r is predicted as p_s r, its miss factor is 1 - P_D P_G r and its "
      "detection factors r P_D N / lambda; the posterior existence and the probabilities given existence are as for "
      "assoc.pda's IPDA; init.existence and delete.existence read it. P_D and lambda as for assoc.gnn. See "
      "docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
      association::AssumedSensor::detection_probability_param(),
      association::AssumedSensor::clutter_density_param(),
      association::initiation_threshold_param(),
      association::survival_probability_param("JIPDA", "JPDA"),
      ParamSpec::integer("max_events", "a cluster with at most this many joint events is enumerated exactly; a larger "
                                       "one by the approximation (at most 1e7: about 0.1 s per cluster)")
          .def("10000")
          .at_least(1)
          .at_most(1e7),
      ParamSpec::choice<JpdaSettings::Approximation>(
          "approximation",
          {{JpdaSettings::Approximation::BeliefPropagation, "belief_propagation"}, {JpdaSettings::Approximation::KBest, "k_best"}},
          "above max_events: loopy belief propagation (Williams & Lau 2014), or the k most likely joint events (Murty's "
          "ranking over the cluster's assignment matrix)")
          .def("belief_propagation"),
      ParamSpec::integer("k_best", "approximation: k_best: the number of joint events kept").def("100").at_least(1).at_most(100000),
      ParamSpec::real("lbp_tolerance", Dimension{}, "belief propagation stops when no message changes by more than this (relative)")
          .def("1e-9")
          .positive(),
      ParamSpec::integer("lbp_max_iterations", "belief propagation stops after this many rounds (counted as unconverged)")
          .def("1000")
          .at_least(1)
          .at_most(1000000),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.jpda", trackflow::register_components)
