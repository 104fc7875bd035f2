// Purpose: init.score — two-point track initiation (the pairing of init.m_of_n) with score-based confirmation: a tentative track is confirmed when its log-likelihood-ratio score reaches Wald's upper SPRT threshold and fails at the lower one, or after max_looks undecided.
#include "initiation/two_point_pairing.hpp"

#include <trackflow/error.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

struct ScoreSettings {
  initiation::PairingSettings pairing;
  double alpha = 1e-6;      // false-track confirmation probability
  double beta = 0.1;        // true-track deletion probability
  int max_looks = 10;
  double start_score = 0.0;  // L of the two initiating detections
  std::string node;
};

// Wald's SPRT on the track score L (tracker.hpp, track_score; Blackman & Popoli 1999, §6.2):
// confirm when L >= T_c = ln((1 - beta) / alpha), fail when L <= T_d = ln(beta / (1 - alpha)),
// alpha the probability of confirming a false track, beta that of failing a true one.
class ScoreInitiator final : public Initiator {
 public:
  explicit ScoreInitiator(ScoreSettings s)
      : s_(std::move(s)),
        pairing_(s_.pairing),
        confirm_(std::log((1.0 - s_.beta) / s_.alpha)),
        fail_(std::log(s_.beta / (1.0 - s_.alpha))) {}

  void reset() override { pairing_.reset(); }

  // The tracker scores every look with the scan's P_D and clutter density: without them the
  // score is NaN and the test cannot run, which is said at the first scan, not at a later track.
  void initiate(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) override {
    if (!(scan.detection_probability > 0.0) || !(scan.clutter_density > 0.0))
      throw DataError("init.score (node '" + s_.node + "'): the scan at t=" + std::to_string(scan.time) +
                      " s states no detection probability or no clutter density, which the track score needs "
                      "(sim.scenario states both); use init.m_of_n");
    const std::size_t first = starts.size();
    pairing_.pair(scan, unassigned, starts);
    for (std::size_t k = first; k < starts.size(); ++k) starts[k].score = s_.start_score;
  }

  bool confirmed(const TrackView& t) const override { return score(t) >= confirm_; }
  bool failed(const TrackView& t) const override {
    return !confirmed(t) && (score(t) <= fail_ || t.looks >= s_.max_looks);
  }

 private:
  double score(const TrackView& t) const {
    if (std::isnan(t.score))
      throw DataError("init.score (node '" + s_.node + "'): track " + std::to_string(t.id) +
                      " has no score (a scan stated no detection probability or clutter density)");
    return t.score;
  }

  ScoreSettings s_;
  initiation::TwoPointPairing pairing_;
  double confirm_, fail_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  ScoreSettings s;
  s.node = p.node();
  s.pairing = initiation::pairing_settings(p);
  s.alpha = p.real("false_track_probability");
  s.beta = p.real("true_track_loss_probability");
  // T_d < T_c needs alpha + beta < 1; otherwise no score is undecided and the test is meaningless.
  if (s.alpha + s.beta >= 1.0)
    throw p.error("true_track_loss_probability", "false_track_probability + true_track_loss_probability must be below 1");
  s.max_looks = static_cast<int>(p.integer("max_looks"));
  s.start_score = p.real("start_score");
  return std::make_unique<ScoreInitiator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "init.score";
  d.kind = ComponentKind::Initiator;
  d.summary = "Two-point initiation from detections no track took, confirmed by the track score "
              "(sequential log-likelihood-ratio test)";
  d.doc = std::string(initiation::pairing_doc()) +
          " The track's score L starts at start_score and the tracker adds per look ln(P_D/beta_FA) + ln N(nu; 0, S) for "
          "a detection used and ln(1 - P_D) for a miss (Blackman & Popoli 1999, sec. 6.2), with the scan's P_D "
          "and clutter density beta_FA (a scan without them is refused). Wald's sequential probability ratio "
          "test: the track is confirmed when L >= ln((1 - beta)/alpha) and deleted when L <= ln(beta/(1 - alpha)) "
          "or when max_looks looks pass undecided (alpha: false_track_probability, beta: "
          "true_track_loss_probability). See docs/multi-target.md.";
  d.params = initiation::pairing_params();
  d.params.push_back(ParamSpec::real("false_track_probability", Dimension{},
                                     "alpha: probability of confirming a false track (upper threshold ln((1-beta)/alpha))")
                         .def("1e-6")
                         .positive()
                         .at_most(0.5));
  d.params.push_back(ParamSpec::real("true_track_loss_probability", Dimension{},
                                     "beta: probability of failing a true track (lower threshold ln(beta/(1-alpha)))")
                         .def("0.1")
                         .positive()
                         .at_most(0.5));
  d.params.push_back(
      ParamSpec::integer("max_looks", "a tentative track still undecided after this many looks (the two initiating "
                                      "ones included) is deleted")
          .def("10")
          .at_least(3));
  d.params.push_back(ParamSpec::real("start_score", Dimension{},
                                     "L of a new track after its two initiating detections, e.g. ln(beta_NT/beta_FA) "
                                     "for a new-target density beta_NT (0: they are the reference)")
                         .def("0"));
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("init.score", trackflow::register_components)
