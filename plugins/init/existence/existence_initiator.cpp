// Purpose: init.existence — two-point track initiation (the pairing of init.m_of_n) with confirmation by the track's existence probability (JIPDA, IPDA): a tentative track starts at initial_existence, is confirmed when its existence reaches confirm_existence and fails below fail_existence.
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

struct ExistenceSettings {
  initiation::PairingSettings pairing;
  double initial = 0.2, confirm = 0.95, fail = 0.05;
  int max_looks = 20;
  std::string node;
};

// The existence probability is propagated by the associator (assoc.jpda, assoc.pda with
// survival_probability; association/existence.hpp): this part only starts tracks with their prior
// and reads it (Musicki & Evans 2004, sec. V: confirmation and termination by existence thresholds).
class ExistenceInitiator final : public Initiator {
 public:
  explicit ExistenceInitiator(ExistenceSettings s) : s_(std::move(s)), pairing_(s_.pairing) {}

  bool reads_existence() const override { return true; }
  void reset() override { pairing_.reset(); }

  void initiate(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) override {
    const std::size_t first = starts.size();
    pairing_.pair(scan, unassigned, starts);
    for (std::size_t k = first; k < starts.size(); ++k) starts[k].existence = s_.initial;
  }

  bool confirmed(const TrackView& t) const override { return existence(t) >= s_.confirm; }
  bool failed(const TrackView& t) const override {
    return !confirmed(t) && (existence(t) < s_.fail || t.looks >= s_.max_looks);
  }

 private:
  double existence(const TrackView& t) const {
    if (std::isnan(t.existence))
      throw std::logic_error("init.existence (node '" + s_.node + "'): track " + std::to_string(t.id) +
                             " has no existence probability (the associator keeps none; checked before the run)");
    return t.existence;
  }

  ExistenceSettings s_;
  initiation::TwoPointPairing pairing_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  ExistenceSettings s;
  s.node = p.node();
  s.pairing = initiation::pairing_settings(p);
  s.initial = p.real("initial_existence");
  s.confirm = p.real("confirm_existence");
  s.fail = p.real("fail_existence");
  s.max_looks = static_cast<int>(p.integer("max_looks"));
  if (!(s.fail < s.initial)) throw p.error("fail_existence", "must be below initial_existence, or every track fails at once");
  if (!(s.initial < s.confirm))
    throw p.error("confirm_existence", "must be above initial_existence, or every track is confirmed at once");
  return std::make_unique<ExistenceInitiator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "init.existence";
  d.kind = ComponentKind::Initiator;
  d.summary = "Two-point initiation from detections no track took, confirmed by the track's existence probability (JIPDA, IPDA)";
  d.doc = std::string(initiation::pairing_doc()) +
          " A new track's existence probability starts at initial_existence; the associator (assoc.jpda, or assoc.pda "
          "with survival_probability) propagates it per look (predicted by the survival probability, updated by what the "
          "look saw: Musicki & Evans 2004). The track is confirmed when it reaches confirm_existence, and deleted while "
          "tentative when it falls below fail_existence or max_looks looks pass undecided. An associator that keeps "
          "no existence is refused before the run. See docs/multi-target.md.";
  d.params = initiation::pairing_params();
  d.params.push_back(ParamSpec::real("initial_existence", Dimension{}, "a new track's existence probability")
                         .def("0.2")
                         .positive()
                         .at_most(0.999));
  d.params.push_back(ParamSpec::real("confirm_existence", Dimension{}, "existence at which a tentative track is confirmed")
                         .def("0.95")
                         .positive()
                         .at_most(1));
  d.params.push_back(ParamSpec::real("fail_existence", Dimension{}, "existence below which a tentative track is deleted")
                         .def("0.05")
                         .at_least(0)
                         .at_most(1));
  d.params.push_back(ParamSpec::integer("max_looks", "a tentative track still undecided after this many looks is deleted")
                         .def("20")
                         .at_least(3));
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("init.existence", trackflow::register_components)
