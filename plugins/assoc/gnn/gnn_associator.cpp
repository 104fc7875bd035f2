// Purpose: assoc.gnn — global nearest neighbour: the one assignment of detections to tracks that maximises the joint likelihood ratio against misses and false alarms, inside chi-square gates, solved as a rectangular 2-D assignment (shortest augmenting path).
#include "assignment/linear_assignment.hpp"
#include "association/gating.hpp"

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

// The detection probability and clutter density the associator assumes when a scan does not say.
struct GnnSettings {
  double gate_probability = 0.99;
  double detection_probability = 0.9;
  double clutter_density = std::numeric_limits<double>::quiet_NaN();
  std::string node;
};

// Cost of track i taking detection j, and of track i missing (Blackman & Popoli 1999, §6.2; Bar-Shalom,
// Willett & Tian 2011, §8.3 — the GNN of the likelihood ratio):
//   c_ij   = -log( P_D g_ij / lambda ),  g_ij = N(z_j; z^_i, S_i), only inside the gate NIS_ij <= gamma,
//   c_i0   = -log( 1 - P_D P_G ),
// so minimising the sum over a one-to-one assignment of tracks to detections or to their own
// "missed" column maximises the product of likelihood ratios of the joint hypothesis.
// The matrix is n x (m + n): m detection columns, then one missed column per track (the others +inf).
class GnnAssociator final : public Associator {
 public:
  explicit GnnAssociator(GnnSettings s) : s_(std::move(s)) {}

  void associate(std::span<const TrackView> tracks, const Scan& scan, std::span<int> detection_of_track) override {
    const int n = static_cast<int>(tracks.size()), m = static_cast<int>(scan.detections.size()), cols = m + n;
    const double pd = std::isfinite(scan.detection_probability) ? scan.detection_probability : s_.detection_probability;
    const double lambda = std::isfinite(scan.clutter_density) ? scan.clutter_density : s_.clutter_density;
    if (!(lambda > 0.0))
      throw DataError("assoc.gnn (node '" + s_.node + "'): the scan at t=" + std::to_string(scan.time) +
                      " s states no clutter density; give clutter_density");
    const double log_lambda = std::log(lambda), log_pd = std::log(pd);
    const double missed = -std::log(1.0 - pd * s_.gate_probability);
    cost_.assign(static_cast<size_t>(n) * static_cast<size_t>(cols), kInf);
    for (int i = 0; i < n; ++i) {
      double* row = cost_.data() + static_cast<size_t>(i) * static_cast<size_t>(cols);
      row[m + i] = missed;
      if (!tracks[static_cast<size_t>(i)].predicted || !gate_.set(*tracks[static_cast<size_t>(i)].predicted, scan.sensor.frame))
        continue;
      const double gamma = threshold(gate_.dim());
      for (int j = 0; j < m; ++j) {
        const double nis = gate_.nis(scan.detections[static_cast<size_t>(j)].value);
        if (nis <= gamma) row[j] = -(log_pd + gate_.log_likelihood(nis) - log_lambda);
      }
    }
    solver_.reserve(n, cols);
    const assignment::AssignmentResult r = solver_.solve(std::span<const double>(cost_), n, cols);
    for (int i = 0; i < n; ++i) {
      const int c = r.feasible ? r.column_for_row[static_cast<size_t>(i)] : -1;
      detection_of_track[static_cast<size_t>(i)] = c >= 0 && c < m ? c : -1;
    }
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double threshold(int dim) {
    if (dim != gamma_dim_) {
      gamma_ = chi_square_quantile(dim, s_.gate_probability);
      gamma_dim_ = dim;
    }
    return gamma_;
  }

  GnnSettings s_;
  association::PredictedGate gate_;
  assignment::LinearAssignment solver_;
  std::vector<double> cost_;
  double gamma_ = 0.0;
  int gamma_dim_ = -1;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  GnnSettings s;
  s.node = p.node();
  s.gate_probability = p.real("gate_probability");
  s.detection_probability = p.real("detection_probability");
  s.clutter_density = p.real_or("clutter_density", std::numeric_limits<double>::quiet_NaN());
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
      "assignment), so the tracks' detections maximise the joint likelihood ratio against misses and clutter. "
      "P_D and the clutter density lambda are the scan's when it states them, else the parameters. A detection no "
      "track takes goes to the initiator. See docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
      ParamSpec::real("detection_probability", Dimension{}, "P_D when the scan does not state it").def("0.9").positive().at_most(1),
      ParamSpec::real("clutter_density", Dimension{-3, 0, 0, 0},
                      "false detections per m3 of Cartesian measurement space when the scan does not state it")
          .positive(),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.gnn", trackflow::register_components)
