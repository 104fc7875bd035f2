// Purpose: init.m_of_n — track initiation from the detections no track took, two-point (a detection pairs with one of the previous scan's within the distance a target can cover, max_speed, plus the measurement errors) or one-point (each at rest with a velocity prior bounded by max_speed); the track is confirmed with M hits in its first N looks, or fails.
#include "initiation/two_point_pairing.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <bit>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

enum class Start { TwoPoint, OnePoint };

struct MofNSettings {
  int m = 2, n = 3;
  initiation::PairingSettings pairing;
  Start start = Start::TwoPoint;
  double velocity_sigma = 0.0;  // one_point: the prior's standard deviation per axis
};

// Starts: the shared two-point pairing (plugins/lib/initiation); confirmation: M of N.
class MofNInitiator final : public Initiator {
 public:
  explicit MofNInitiator(MofNSettings s) : s_(s), pairing_(s.pairing) {}

  void reset() override { pairing_.reset(); }

  void initiate(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) override {
    if (s_.start == Start::TwoPoint) return pairing_.pair(scan, unassigned, starts);
    // One point: every detection no track took starts a track at rest (a tentative one: clutter
    // starts them too, and M of N fails those).
    for (int j : unassigned) {
      TrackStart st;
      st.second = j;
      st.velocity_sigma = s_.velocity_sigma;
      starts.push_back(st);
    }
  }
  bool one_point_starts() const override { return s_.start == Start::OnePoint; }

  // M hits among the first N looks (the initiating one or two included).
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
  s.start = p.choice<Start>("start");
  if (s.start == Start::TwoPoint && p.given("velocity_sigma"))
    throw p.error("velocity_sigma", "is the prior of start: one_point; two_point starts take the velocity from the pair");
  if (s.start == Start::OnePoint && p.given("gate_sigmas"))
    throw p.error("gate_sigmas", "is the pairing gate of start: two_point; one_point starts pair nothing");
  s.velocity_sigma = p.has("velocity_sigma") ? p.real("velocity_sigma") : s.pairing.max_speed / 2.0;
  return std::make_unique<MofNInitiator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "init.m_of_n";
  d.kind = ComponentKind::Initiator;
  d.summary = "Two-point or one-point initiation from detections no track took, confirmed by M hits in the first N looks";
  d.doc = std::string("start: two_point (default): ") + initiation::pairing_doc() +
          " start: one_point: every detection no track took starts a tentative track at once, at rest: position "
          "the detection's (its covariance), velocity 0 with standard deviation velocity_sigma per axis (default "
          "max_speed / 2: a target at max_speed along an axis is 2 sigma out), the estimator's own initial "
          "acceleration sigma (Estimator::initiate_one_point; filter.kalman, filter.ekf and filter.ukf offer it, "
          "others are refused before the run); one hit. The track is confirmed when it has m hits in its first n "
          "looks (the initiating one or two included), and deleted when n looks pass without. See docs/multi-target.md.";
  d.params = {
      ParamSpec::integer("m", "hits that confirm a tentative track").def("3").at_least(2),
      ParamSpec::integer("n", "within its first n looks (the initiating ones included)").def("4").at_least(2).at_most(64),
      ParamSpec::choice<Start>("start", {{Start::TwoPoint, "two_point"}, {Start::OnePoint, "one_point"}},
                               "pair two scans' detections, or start from each detection at rest with a velocity prior")
          .def("two_point"),
      ParamSpec::real("velocity_sigma", dim::velocity,
                      "one_point: the velocity prior's standard deviation per axis (default max_speed / 2)")
          .positive(),
  };
  for (ParamSpec& spec : initiation::pairing_params()) d.params.push_back(std::move(spec));
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("init.m_of_n", trackflow::register_components)
