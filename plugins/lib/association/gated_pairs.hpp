// Purpose: every (track, detection) pair of a scan inside the track's chi-square gate, with its NIS and log-likelihood; a spatial grid pre-gate for Cartesian scans so the cost grows with the pairs, not with tracks x detections.
#pragma once

#include "association/gating.hpp"
#include "memory/grow.hpp"
#include "association/point_grid.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace trackflow::association {

struct GatedPair {
  int track = 0, detection = 0;
  double nis = 0.0, log_likelihood = 0.0;
};

// For each track with a predicted measurement (a positive definite S), the detections with
// NIS = nu' S^-1 nu <= gamma = chi2inv(P_G, dim) (gating.hpp; the azimuth residual wrapped).
//
// Pre-gate: on a Cartesian or planar scan the detections are binned by (x, y) in a PointGrid whose cell
// side is the median over the tracks of their gate's width; a track tests only the detections in
// the cells its gate's bounding box overlaps. The box is exact, not a heuristic: on the ellipsoid
// nu' S^-1 nu <= gamma, |nu_k| <= sqrt(gamma S_kk) (the maximum of a linear function over an
// ellipsoid). So the pairs are exactly those of the all-pairs test, and the NIS of each pair is
// computed the same way. Other frames (range, azimuth, elevation) test all pairs.
//
// Order: pairs by track, then in the grid's order; callers that need an order sort (assoc.nearest)
// or do not depend on it (assoc.gnn's clustered assignment).
class GatedPairs {
 public:
  explicit GatedPairs(double gate_probability) : gate_probability_(gate_probability) {}

  std::span<const GatedPair> find(std::span<const TrackView> tracks, const Scan& scan) {
    pairs_.clear();
    const std::size_t n = tracks.size(), m = scan.detections.size();
    if (n == 0 || m == 0) return pairs_;
    gates_.resize(n);
    memory::assign_grown(ok_, n, char{0});
    widths_.clear();
    // Cartesian and planar detections start with (x, y): both bin by it.
    const bool xy = scan.sensor.frame == Frame::Cartesian || scan.sensor.frame == Frame::Planar;
    for (std::size_t i = 0; i < n; ++i) {
      if (!tracks[i].predicted || !gates_[i].set(*tracks[i].predicted, scan.sensor.frame)) continue;
      ok_[i] = 1;
      if (xy) {
        const MeasCov& S = tracks[i].predicted->S;
        widths_.push_back(2.0 * std::sqrt(threshold(gates_[i].dim()) * std::max(S(0, 0), S(1, 1))));
      }
    }
    const bool grid = xy && !widths_.empty();
    if (grid) {
      points_.resize(m);
      for (std::size_t j = 0; j < m; ++j) points_[j] = scan.detections[j].value.head<2>();
      const auto mid = widths_.begin() + static_cast<std::ptrdiff_t>(widths_.size() / 2);
      std::nth_element(widths_.begin(), mid, widths_.end());
      grid_.build(points_, *mid);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!ok_[i]) continue;
      const PredictedGate& g = gates_[i];
      const double gamma = threshold(g.dim());
      auto test = [&](int j) {
        const double nis = g.nis(scan.detections[static_cast<std::size_t>(j)].value);
        if (nis <= gamma) pairs_.push_back({static_cast<int>(i), j, nis, g.log_likelihood(nis)});
      };
      if (grid) {
        const PredictedMeasurement& p = *tracks[i].predicted;
        const Eigen::Vector2d half(std::sqrt(gamma * p.S(0, 0)), std::sqrt(gamma * p.S(1, 1)));
        const Eigen::Vector2d centre = p.z.head<2>();
        grid_.for_each_candidate(centre - half, centre + half, test);
      } else {
        for (std::size_t j = 0; j < m; ++j) test(static_cast<int>(j));
      }
    }
    return pairs_;
  }

  double gate_probability() const { return gate_probability_; }

 private:
  double threshold(int dim) {
    if (dim != gamma_dim_) {
      gamma_ = chi_square_quantile(dim, gate_probability_);
      gamma_dim_ = dim;
    }
    return gamma_;
  }

  double gate_probability_;
  double gamma_ = 0.0;
  int gamma_dim_ = -1;
  std::vector<PredictedGate> gates_;
  std::vector<char> ok_;
  std::vector<double> widths_;
  std::vector<Eigen::Vector2d> points_;
  PointGrid grid_;
  std::vector<GatedPair> pairs_;
};

}  // namespace trackflow::association
