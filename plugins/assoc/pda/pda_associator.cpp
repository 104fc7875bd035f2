// Purpose: assoc.pda — probabilistic data association, each track on its own: the probability that each detection in its gate is the track's, and that none is (Bar-Shalom & Tse 1975), for a combined update through the track's estimator.
#include "association/assumed_sensor.hpp"
#include "association/existence.hpp"
#include "association/gated_pairs.hpp"
#include "association/probabilistic_params.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// The PDA's association probabilities (Bar-Shalom & Tse 1975, "Tracking in a cluttered environment
// with probabilistic data association", Automatica 11:451-460; Bar-Shalom, Willett & Tian 2011,
// "Tracking and Data Fusion", eq. 3.4.3-8 in the parametric form with clutter density lambda):
//   beta_j = l_j / (w_0 + sum_k l_k),  beta_0 = w_0 / (w_0 + sum_k l_k),
//   l_j = P_D N(z_j; z^, S) / lambda  (gated: NIS_j <= chi2inv(P_G, dim)),  w_0 = 1 - P_D P_G.
// Each track on its own: a detection may enter several tracks' mixtures (assoc.jpda accounts for
// that). Computed from log-likelihoods relative to the largest term, so no term under- or overflows.
class PdaAssociator final : public Associator {
 public:
  PdaAssociator(double gate_probability, association::AssumedSensor sensor, double initiation_threshold, double survival)
      : gate_probability_(gate_probability), sensor_(std::move(sensor)), initiation_threshold_(initiation_threshold),
        survival_(survival), gated_(gate_probability) {}

  bool probabilistic() const override { return true; }
  bool keeps_existence() const override { return survival_ > 0.0; }
  void associate(std::span<const TrackView>, const Scan&, std::span<int>) override {
    throw std::logic_error("assoc.pda gives association probabilities (associate_probabilities)");
  }

  void associate_probabilities(std::span<const TrackView> tracks, const Scan& scan, AssociationProbabilities& out) override {
    out.initiation_threshold = initiation_threshold_;
    const double pd = sensor_.detection_probability(scan);
    const double pd_pg = pd * gate_probability_;
    // A look without detections needs no clutter density (nothing is weighed against clutter).
    const double log_ratio = scan.detections.empty() ? 0.0 : std::log(pd) - std::log(sensor_.clutter_density(scan));
    const std::span<const association::GatedPair> pairs =
        scan.detections.empty() ? std::span<const association::GatedPair>() : gated_.find(tracks, scan);
    // Pairs come grouped by track, tracks ascending (gated_pairs.hpp).
    std::size_t b = 0;
    for (int i = 0; i < static_cast<int>(tracks.size()); ++i) {
      std::size_t e = b;
      while (e < pairs.size() && pairs[e].track == i) ++e;
      // IPDA: the existence-weighted factors; plain PDA: r = 1 with the same formulas' r-free form.
      const double r = keeps_existence() ? association::predicted_existence(existing(tracks[static_cast<size_t>(i)]), survival_) : 1.0;
      const double log_none = association::log_miss_factor(r, pd_pg);
      const double log_r = r > 0.0 ? association::log_detection_factor(r) : -std::numeric_limits<double>::infinity();
      double top = log_none;
      for (std::size_t k = b; k < e; ++k) top = std::max(top, log_r + log_ratio + pairs[k].log_likelihood);
      double sum = std::exp(log_none - top);
      for (std::size_t k = b; k < e; ++k) sum += std::exp(log_r + log_ratio + pairs[k].log_likelihood - top);
      beta_.clear();
      for (std::size_t k = b; k < e; ++k) beta_.push_back(std::exp(log_r + log_ratio + pairs[k].log_likelihood - top) / sum);
      double none = std::exp(log_none - top) / sum;
      if (keeps_existence()) out.set_existence(i, association::condition_on_existence(r, pd_pg, beta_, none));
      for (std::size_t k = b; k < e; ++k) out.add(i, pairs[k].detection, beta_[k - b]);
      out.set_none(i, none);
      b = e;
    }
  }

 private:
  // A track started without an existence (init.m_of_n, init.score) is taken as a target: r = 1.
  static double existing(const TrackView& v) { return std::isnan(v.existence) ? 1.0 : v.existence; }

  double gate_probability_;
  association::AssumedSensor sensor_;
  double initiation_threshold_;
  double survival_;  // > 0: IPDA (existence kept); 0: PDA
  association::GatedPairs gated_;
  std::vector<double> beta_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  return std::make_unique<PdaAssociator>(p.real("gate_probability"),
                                         association::AssumedSensor(p, "assoc.pda (node '" + p.node() + "')"),
                                         p.real("initiation_threshold"), p.real_or("survival_probability", 0.0));
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "assoc.pda";
  d.kind = ComponentKind::Associator;
  d.summary = "Probabilistic data association, each track on its own (Bar-Shalom & Tse 1975): every gated detection "
              "weighted by its probability in one combined update";
  d.doc =
      "For each track, the detections in its gate NIS <= chi2inv(P_G, dim) with l_j = P_D N(z_j; z^, S) / lambda, "
      "and the miss weight w_0 = 1 - P_D P_G: beta_j = l_j / (w_0 + sum l), beta_0 = w_0 / (w_0 + sum l) (Bar-Shalom, "
      "Willett & Tian 2011, eq. 3.4.3-8). The tracker updates the track with all of them at once: the moment-matched "
      "mixture of the prediction (weight beta_0) and the update with each detection (Estimator::update_weighted; for "
      "a Kalman-form update exactly the PDA's combined update). Each track on its own: two tracks may both weight "
      "the same detection (assoc.jpda accounts for the competition). A detection whose summed probability over the "
      "tracks exceeds initiation_threshold starts no track. P_D and lambda as for assoc.gnn. With "
      "survival_probability p_s: IPDA (Musicki, Evans & Stankovic 1994) - each track's existence r is predicted as "
      "p_s r, the miss weight becomes 1 - P_D P_G r and l_j becomes r l_j, the posterior existence is sum beta_j + "
      "beta_0 (1 - P_D P_G) r / (1 - P_D P_G r), and the update mixes the probabilities given existence; a track "
      "started without an existence (init.m_of_n, init.score) starts at r = 1. See docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
      association::AssumedSensor::detection_probability_param(),
      association::AssumedSensor::clutter_density_param(),
      association::initiation_threshold_param(),
      association::survival_probability_param("IPDA", "PDA"),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.pda", trackflow::register_components)
