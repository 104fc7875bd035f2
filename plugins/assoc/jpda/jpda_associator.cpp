// Purpose: assoc.jpda — joint probabilistic data association: per cluster of tracks that share gated detections, the marginal probability that each detection is each track's over all joint events (exact enumeration up to max_events, loopy belief propagation above), optionally with each track's existence (JIPDA), for a combined update through each track's estimator.
#include "association/assumed_sensor.hpp"
#include "association/existence.hpp"
#include "association/gated_pairs.hpp"
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
  association::LbpOptions lbp;
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
      const association::JpdaReport report = marginals_.marginals(cl, log_miss_, s_.max_events, s_.lbp);
      if (report.method == association::JpdaMethod::exact) {
        ++out.exact_clusters;
      } else {
        ++out.approximate_clusters;
        if (!report.lbp.converged) ++out.unconverged_clusters;
      }
      for (std::size_t t = 0; t < cl.tracks.size(); ++t) none_[static_cast<std::size_t>(cl.tracks[t])] = marginals_.miss_beta()[t];
      for (std::size_t k = 0; k < cl.pairs.size(); ++k)
        pair_beta_[static_cast<std::size_t>(cl.pairs[k].source)] = marginals_.pair_beta()[k];
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
      "two detections), the choice counted per scan in the tracker's summary. The tracker updates each track with its "
      "candidates at once (the combined update, as for assoc.pda). With survival_probability p_s: JIPDA (Musicki & "
      "Evans 2004) - each track's existence r is predicted as p_s r, its miss factor is 1 - P_D P_G r and its "
      "detection factors r P_D N / lambda; the posterior existence and the probabilities given existence are as for "
      "assoc.pda's IPDA; init.existence and delete.existence read it. P_D and lambda as for assoc.gnn. See "
      "docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
      association::AssumedSensor::detection_probability_param(),
      association::AssumedSensor::clutter_density_param(),
      ParamSpec::real("initiation_threshold", Dimension{},
                      "a detection whose probability of being some track's is at most this goes to the initiator "
                      "(0: any detection in a gate starts no track)")
          .def("0")
          .at_least(0)
          .at_most(1),
      ParamSpec::real("survival_probability", Dimension{},
                      "JIPDA: keep each track's existence probability, a target surviving from one look to the next "
                      "with this probability (default: JPDA, no existence)")
          .positive()
          .at_most(1),
      ParamSpec::integer("max_events", "a cluster with at most this many joint events is enumerated exactly; a larger "
                                       "one by loopy belief propagation")
          .def("10000")
          .at_least(1),
      ParamSpec::real("lbp_tolerance", Dimension{}, "belief propagation stops when no message changes by more than this (relative)")
          .def("1e-9")
          .positive(),
      ParamSpec::integer("lbp_max_iterations", "belief propagation stops after this many rounds (counted as unconverged)")
          .def("1000")
          .at_least(1),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.jpda", trackflow::register_components)
