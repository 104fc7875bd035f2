// Purpose: assoc.gnn — global nearest neighbour: the one assignment of detections to tracks that maximises the joint likelihood ratio against misses and false alarms, inside chi-square gates, solved as a rectangular 2-D assignment (shortest augmenting path).
#include "assignment/sparse_assignment.hpp"
#include "association/assumed_sensor.hpp"
#include "association/gated_pairs.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// What the associator assumes: its gate, and P_D and the clutter density (association/assumed_sensor.hpp).
struct GnnSettings {
  double gate_probability = 0.99;
  association::AssumedSensor sensor;
};

// Cost of track i taking detection j, and of track i missing (Blackman & Popoli 1999, §6.2; Bar-Shalom,
// Willett & Tian 2011, §8.3 — the GNN of the likelihood ratio):
//   c_ij   = -log( P_D g_ij / lambda ),  g_ij = N(z_j; z^_i, S_i), only inside the gate NIS_ij <= gamma,
//   c_i0   = -log( 1 - P_D P_G ),
// so minimising the sum over a one-to-one assignment of tracks to detections or to their own
// "missed" column maximises the product of likelihood ratios of the joint hypothesis.
// The matrix is n x (m + n): m detection columns, then one missed column per track (the others +inf),
// held sparse (gated pairs only) and solved exactly per cluster of competing tracks.
class GnnAssociator final : public Associator {
 public:
  explicit GnnAssociator(GnnSettings s) : s_(std::move(s)) {}

  void associate(std::span<const TrackView> tracks, const Scan& scan, std::span<int> detection_of_track) override {
    const int n = static_cast<int>(tracks.size()), m = static_cast<int>(scan.detections.size());
    const double pd = s_.sensor.detection_probability(scan);
    const double lambda = s_.sensor.clutter_density(scan);
    const double log_lambda = std::log(lambda), log_pd = std::log(pd);
    const double missed = -std::log(1.0 - pd * s_.gate_probability);
    // Only gated pairs enter; the clustered solver splits the problem into the groups of tracks
    // that compete for detections, each solved exactly (sparse_assignment.hpp).
    problem_.clear(n, m);
    for (int i = 0; i < n; ++i) problem_.set_none_cost(i, missed);
    for (const association::GatedPair& g : gated_.find(tracks, scan))
      problem_.add(g.track, g.detection, -(log_pd + g.log_likelihood - log_lambda));
    const std::span<const int> col = problem_.solve();
    for (int i = 0; i < n; ++i) detection_of_track[static_cast<size_t>(i)] = col[static_cast<size_t>(i)];
  }

 private:
  GnnSettings s_;
  association::GatedPairs gated_{s_.gate_probability};
  assignment::SparseAssignment problem_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  GnnSettings s;
  s.gate_probability = p.real("gate_probability");
  s.sensor = association::AssumedSensor(p, "assoc.gnn (node '" + p.node() + "')");
  return std::make_unique<GnnAssociator>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "assoc.gnn";
  d.kind = ComponentKind::Associator;
  d.summary = "Global nearest neighbour: the jointly most likely assignment of detections to tracks (2-D assignment "
              "with miss and false-alarm alternatives, chi-square gates)";
  d.doc =
      "Cost of track i taking detection j: -log(P_D N(z_j; z^_i, S_i) / lambda) inside the gate NIS <= chi2inv(P_G, "
      "dim); of track i taking none: -log(1 - P_D P_G). The n x (m + n) matrix (one missed column per track) is "
      "solved exactly by the shortest augmenting path method (Jonker-Volgenant, Crouse 2016; plugins/lib/"
      "assignment), so the tracks' detections maximise the joint likelihood ratio against misses and clutter; it is "
      "held sparse (gated pairs only; a grid over the detections finds each gate's candidates exactly: by (x, y) on "
      "Cartesian scans, by (range, azimuth, elevation) across the azimuth seam on spherical ones) "
      "and solved per cluster of tracks that share gated detections, which gives the same optimum. "
      "P_D and the clutter density lambda are the parameters when given (a model of the sensor that may differ from "
      "the truth, for mismatch studies), else the scan's (sim.scenario states its own), else P_D = 0.9; a scan "
      "without a clutter density then needs clutter_density. A detection no "
      "track takes goes to the initiator. See docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
      association::AssumedSensor::detection_probability_param(),
      association::AssumedSensor::clutter_density_param(),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.gnn", trackflow::register_components)
