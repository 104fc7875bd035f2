// Purpose: assoc.nearest — the naive baseline: gated track-detection pairs taken greedily in order of increasing NIS, each track and detection once.
#include "association/gated_pairs.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

namespace trackflow {
namespace {

class NearestAssociator final : public Associator {
 public:
  explicit NearestAssociator(double gate_probability) : gated_(gate_probability) {}

  void associate(std::span<const TrackView> tracks, const Scan& scan, std::span<int> detection_of_track) override {
    for (size_t i = 0; i < tracks.size(); ++i) detection_of_track[i] = -1;
    pairs_.clear();
    for (const association::GatedPair& g : gated_.find(tracks, scan)) pairs_.push_back({g.nis, g.track, g.detection});
    // Smallest NIS first; ties by track, then detection, so the result never depends on sort order.
    std::sort(pairs_.begin(), pairs_.end(), [](const Pair& a, const Pair& b) {
      return std::tie(a.nis, a.track, a.detection) < std::tie(b.nis, b.track, b.detection);
    });
    taken_.assign(scan.detections.size(), 0);
    for (const Pair& p : pairs_) {
      if (detection_of_track[static_cast<size_t>(p.track)] >= 0 || taken_[static_cast<size_t>(p.detection)]) continue;
      detection_of_track[static_cast<size_t>(p.track)] = p.detection;
      taken_[static_cast<size_t>(p.detection)] = 1;
    }
  }

 private:
  struct Pair {
    double nis;
    int track, detection;
  };
  association::GatedPairs gated_;
  std::vector<Pair> pairs_;
  std::vector<char> taken_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  return std::make_unique<NearestAssociator>(p.real("gate_probability"));
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "assoc.nearest";
  d.kind = ComponentKind::Associator;
  d.summary = "Greedy nearest neighbour: gated pairs taken in order of increasing NIS (the baseline for assoc.gnn)";
  d.doc =
      "Every track-detection pair inside the gate NIS <= chi2inv(P_G, dim) is sorted by NIS (ties by track, then "
      "detection); pairs are taken in that order while neither side is taken. Locally, not jointly, best: at "
      "crossings it can give a track its neighbour's detection where assoc.gnn would not. See docs/multi-target.md.";
  d.params = {
      association::gate_probability_param(),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("assoc.nearest", trackflow::register_components)
