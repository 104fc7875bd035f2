// Purpose: init.m_of_n — two-point track initiation: a detection no track took pairs with one of the previous scan's within the distance a target can cover (max_speed) plus the measurement errors; the track is confirmed with M hits in its first N looks, or fails.
#include "initiation/two_point_pairing.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <bit>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

struct MofNSettings {
  int m = 2, n = 3;
  initiation::PairingSettings pairing;
};

// Starts: the shared two-point pairing (plugins/lib/initiation); confirmation: M of N.
class MofNInitiator final : public Initiator {
 public:
  explicit MofNInitiator(MofNSettings s) : s_(s), pairing_(s.pairing) {}

  void reset() override { pairing_.reset(); }

  void initiate(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) override {
    pairing_.pair(scan, unassigned, starts);
  }

  // M hits among the first N looks (the two initiating ones included).
  bool confirmed(const TrackView& t) const override { return t.looks <= s_.n && std::popcount(t.history) >= s_.m; }
  bool failed(const TrackView& t) const override { return t.looks >= s_.n && !confirmed(t); }

 private:
  MofNSettings s_;
  initiation::TwoPointPairing pairing_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  MofNSettings s;
  s.m = static_cast<int>(p.integer("m"));
  s.n = static_cast<int>(p.integer("n"));
  if (s.m > s.n) throw p.error("m", "m (" + std::to_string(s.m) + ") cannot exceed n (" + std::to_string(s.n) + ")");
  s.pairing = initiation::pairing_settings(p);
  return std::make_unique<MofNInitiator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "init.m_of_n";
  d.kind = ComponentKind::Initiator;
  d.summary = "Two-point initiation from detections no track took, confirmed by M hits in the first N looks";
  d.doc = std::string(initiation::pairing_doc()) +
          " The track is confirmed when it has m hits in its first n looks (the initiating two included), and "
          "deleted when n looks pass without. See docs/multi-target.md.";
  d.params = {
      ParamSpec::integer("m", "hits that confirm a tentative track").def("3").at_least(2),
      ParamSpec::integer("n", "within its first n looks (the two initiating ones included)").def("4").at_least(2).at_most(64),
  };
  for (ParamSpec& spec : initiation::pairing_params()) d.params.push_back(std::move(spec));
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("init.m_of_n", trackflow::register_components)
