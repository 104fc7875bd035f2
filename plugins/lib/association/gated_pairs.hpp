// Purpose: every (track, detection) pair of a scan inside the track's chi-square gate, with its NIS and log-likelihood; a spatial grid pre-gate (Cartesian (x, y); spherical (range, azimuth, elevation) with the azimuth seam) so the cost grows with the pairs, not with tracks x detections.
#pragma once

#include "association/gating.hpp"
#include "memory/grow.hpp"
#include "association/point_grid.hpp"
#include "association/spherical_grid.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <array>
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
// Pre-gate: a track tests only the detections in the grid cells its gate's bounding box overlaps.
// The box is exact, not a heuristic: on the ellipsoid nu' S^-1 nu <= gamma, |nu_k| <= sqrt(gamma
// S_kk) (the maximum of a linear function over an ellipsoid; it holds for any subset of the axes, so
// a box over the leading 2 or 3 of 4 values — range rate last — is exact too). So the pairs are
// exactly those of the all-pairs test, and the NIS of each pair is computed the same way.
//   - Cartesian or planar scan: the detections are binned by (x, y) in a PointGrid whose cell side
//     is the median over the tracks of their gate's width.
//   - Spherical or polar scan: binned by (range, azimuth(, elevation)) in a SphericalGrid, the cell side per
//     axis the median over the tracks of the gate's width along it; the azimuth interval is taken
//     modulo 2 pi (a box across the ±pi seam queries both sides; a gate wider than the circle, near
//     the sensor or the zenith, takes every azimuth). The axes binned are the leading
//     min(3, measurement size) values of a spherical scan and the (range, azimuth) of a polar one.
//     The box is widened by a relative 1e-6 and an absolute 1e-9 (1 + |z_k|) so that rounding in the
//     NIS, in the azimuth wrap or in a cell index never drops a pair at the gate's edge. A track
//     whose predicted measurement is not finite tests every detection, as before.
//
// Order: pairs by track. Within a track: Cartesian, in the grid's order; spherical, by detection
// index — the order of the all-pairs test it replaced, so that every result on spherical scans is
// the same to the bit as before the grid. Callers that need an order sort (assoc.nearest: by NIS,
// track, detection) or do not depend on it (assoc.gnn's clustered assignment).
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
    for (auto& w : axis_widths_) w.clear();
    // Cartesian and planar detections start with (x, y): both bin by it.
    const bool cartesian = scan.sensor.frame == Frame::Cartesian || scan.sensor.frame == Frame::Planar;
    // The frames whose values are [range, azimuth(, elevation)(, range rate)] with the azimuth
    // residual wrapped by the gate (gating.hpp): spherical and polar. `axes`: how many leading
    // values are binned, min(3, every track's and detection's value count); a polar scan's 2 (its
    // third value, when there is one, is the range rate).
    const bool spherical = has_azimuth(scan.sensor.frame);
    int axes = scan.sensor.frame == Frame::Polar ? 2 : 3;
    for (std::size_t i = 0; i < n; ++i) {
      if (!tracks[i].predicted || !gates_[i].set(*tracks[i].predicted, scan.sensor.frame)) continue;
      ok_[i] = 1;
      const MeasCov& S = tracks[i].predicted->S;
      const double gamma = threshold(gates_[i].dim());
      if (cartesian) widths_.push_back(2.0 * std::sqrt(gamma * std::max(S(0, 0), S(1, 1))));
      if (spherical) {
        axes = std::min(axes, gates_[i].dim());
        for (int k = 0; k < std::min(3, gates_[i].dim()); ++k) {
          const double w = 2.0 * std::sqrt(gamma * S(k, k));
          if (std::isfinite(w)) axis_widths_[static_cast<std::size_t>(k)].push_back(w);
        }
      }
    }
    const bool grid = cartesian && !widths_.empty();
    if (grid) {
      points_.resize(m);
      for (std::size_t j = 0; j < m; ++j) points_[j] = scan.detections[j].value.head<2>();
      grid_.build(points_, median(widths_));
    }
    bool polar_grid = false;
    if (spherical) {
      for (std::size_t j = 0; j < m; ++j) axes = std::min(axes, static_cast<int>(scan.detections[j].value.size()));
      polar_grid = axes >= 2 && !axis_widths_[0].empty();
    }
    if (polar_grid) {
      polar_points_.resize(m);
      for (std::size_t j = 0; j < m; ++j) {
        const MeasVec& v = scan.detections[j].value;
        polar_points_[j] = Eigen::Vector3d(v(0), v(1), axes >= 3 ? v(2) : 0.0);
      }
      Eigen::Vector3d cell = Eigen::Vector3d::Zero();
      for (int k = 0; k < axes; ++k) cell(k) = median(axis_widths_[static_cast<std::size_t>(k)]);
      polar_grid_.build(polar_points_, axes, cell);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!ok_[i]) continue;
      const PredictedGate& g = gates_[i];
      const double gamma = threshold(g.dim());
      auto test = [&](int j) {
        const double nis = g.nis(scan.detections[static_cast<std::size_t>(j)].value);
        if (nis <= gamma) pairs_.push_back({static_cast<int>(i), j, nis, g.log_likelihood(nis)});
      };
      const PredictedMeasurement& p = *tracks[i].predicted;
      if (grid) {
        const Eigen::Vector2d half(std::sqrt(gamma * p.S(0, 0)), std::sqrt(gamma * p.S(1, 1)));
        const Eigen::Vector2d centre = p.z.head<2>();
        grid_.for_each_candidate(centre - half, centre + half, test);
        continue;
      }
      if (polar_grid) {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero(), half = Eigen::Vector3d::Zero();
        for (int k = 0; k < axes; ++k) {
          centre(k) = p.z(k);
          half(k) = std::sqrt(gamma * p.S(k, k)) * (1.0 + 1e-6) + 1e-9 * (1.0 + std::fabs(p.z(k)));
        }
        if (centre.allFinite() && !half.hasNaN()) {
          const std::size_t first = pairs_.size();
          polar_grid_.for_each_candidate(centre, half, test);
          // The grid lists cell by cell; the all-pairs test's order is by detection.
          std::sort(pairs_.begin() + static_cast<std::ptrdiff_t>(first), pairs_.end(),
                    [](const GatedPair& a, const GatedPair& b) { return a.detection < b.detection; });
          continue;
        }
      }
      for (std::size_t j = 0; j < m; ++j) test(static_cast<int>(j));
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

  // The median of `v` (reordered); 0 (one cell) when empty.
  static double median(std::vector<double>& v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  }

  double gate_probability_;
  double gamma_ = 0.0;
  int gamma_dim_ = -1;
  std::vector<PredictedGate> gates_;
  std::vector<char> ok_;
  std::vector<double> widths_;
  std::vector<Eigen::Vector2d> points_;
  PointGrid grid_;
  std::array<std::vector<double>, 3> axis_widths_;
  std::vector<Eigen::Vector3d> polar_points_;
  SphericalGrid polar_grid_;
  std::vector<GatedPair> pairs_;
};

}  // namespace trackflow::association
