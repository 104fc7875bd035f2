// Purpose: a uniform grid over detections in measurement coordinates (range, azimuth, optionally elevation) with the azimuth periodic, listing the candidates near a box that may cross the ±pi seam: the coarse pre-gate of spherical scans.
#pragma once

#include "memory/grow.hpp"

#include <trackflow/geometry.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

namespace trackflow::association {

// Points are [range, azimuth, elevation] (metres, radians); `axes` = 3 bins all three, 2 bins
// (range, azimuth) only, for a range-azimuth frame or when the elevation is absent. Axis 1 is the
// azimuth: a point is binned by its azimuth wrapped to (-pi, pi], and a query box's azimuth
// interval is taken modulo 2 pi. The other axes are plain intervals.
//
// for_each_candidate(centre, half, f) calls f(point index) exactly once for every point in a cell
// that overlaps the box |v_k - centre_k| <= half_k (azimuth: |wrap(v_1 - centre_1)| <= half_1): a
// superset of the points inside the box, which the caller then tests exactly (a chi-square gate).
//   - An azimuth interval that crosses the seam (centre ± half beyond ±pi) is queried on both sides;
//     when the two sides meet in one cell column they are merged, so no cell is visited twice.
//   - half_1 >= pi (a gate wider than the circle: a target near the sensor or near the zenith, where
//     the azimuth variance is huge) takes every azimuth cell; range and elevation still restrict.
//   - A half-width may be +inf (every cell of that axis). The centre must be finite.
// A point with a non-finite coordinate lies in no box and is never listed.
//
// Cell sides are the caller's wish per axis (e.g. the median gate width along it), grown together
// by 1.5 until the grid has at most about 2 x points + 16 cells, so a box larger than the whole grid
// costs O(points), as testing every point would (the same rule as PointGrid). Within a query the
// order is fixed (cells by elevation, azimuth, range; points in index order within a cell), so
// results depend on nothing but the input.
//
// Storage: members, grown by the largest input seen; after that build() allocates nothing.
class SphericalGrid {
 public:
  static constexpr int kAzimuth = 1;

  // `cell`: the wanted side per axis; <= 0 or non-finite: one cell along that axis.
  void build(std::span<const Eigen::Vector3d> points, int axes, const Eigen::Vector3d& cell) {
    axes_ = std::clamp(axes, 2, 3);
    n_ = {1, 1, 1};
    lo_ = Eigen::Vector3d::Zero();
    inv_cell_ = Eigen::Vector3d::Zero();
    const std::size_t n = points.size();
    binned_.resize(n);
    bool any = false;
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      Eigen::Vector3d p = points[i];
      if (axes_ < 3) p(2) = 0.0;
      p(kAzimuth) = wrap_angle(p(kAzimuth));
      binned_[i] = p;
      if (!p.allFinite()) continue;
      if (!any) lo = hi = p;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      any = true;
    }
    if (any) {
      lo_ = lo;
      const Eigen::Vector3d extent = hi - lo;
      Eigen::Vector3d side;
      for (int k = 0; k < 3; ++k) side(k) = std::isfinite(cell(k)) && cell(k) > 0.0 ? cell(k) : HUGE_VAL;
      const double max_cells = 2.0 * static_cast<double>(n) + 16.0;
      auto count = [&] {
        double c = 1.0;
        for (int k = 0; k < axes_; ++k) c *= std::floor(extent(k) * (1.0 / side(k))) + 1.0;
        return c;
      };
      // Grow the sides together until the grid has at most max_cells cells.
      while (!(count() <= max_cells)) side *= 1.5;
      for (int k = 0; k < axes_; ++k) {
        inv_cell_(k) = 1.0 / side(k);
        n_[static_cast<std::size_t>(k)] = static_cast<int>(std::floor(extent(k) * inv_cell_(k))) + 1;
      }
    }
    const std::size_t cells = static_cast<std::size_t>(n_[0]) * static_cast<std::size_t>(n_[1]) * static_cast<std::size_t>(n_[2]);
    memory::assign_grown(start_, cells + 1, 0);
    cell_of_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (!binned_[i].allFinite()) {
        cell_of_[i] = -1;
        continue;
      }
      const auto c = static_cast<std::size_t>(cell_index(binned_[i]));
      cell_of_[i] = static_cast<int>(c);
      ++start_[c + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    memory::reserve_grown(fill_, cells);
    fill_.assign(start_.begin(), start_.end() - 1);
    sorted_.resize(static_cast<std::size_t>(start_[cells]));
    for (std::size_t i = 0; i < n; ++i)
      if (cell_of_[i] >= 0) sorted_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(cell_of_[i])]++)] = static_cast<int>(i);
  }

  template <class F>
  void for_each_candidate(const Eigen::Vector3d& centre, const Eigen::Vector3d& half, F&& f) const {
    if (sorted_.empty()) return;
    const int r0 = clamp(0, centre(0) - half(0)), r1 = clamp(0, centre(0) + half(0));
    int e0 = 0, e1 = 0;
    if (axes_ == 3) {
      e0 = clamp(2, centre(2) - half(2));
      e1 = clamp(2, centre(2) + half(2));
    }
    const int last = n_[kAzimuth] - 1;
    auto visit = [&](int a0, int a1) {
      for (int e = e0; e <= e1; ++e)
        for (int a = a0; a <= a1; ++a) {
          const std::size_t row = (static_cast<std::size_t>(e) * static_cast<std::size_t>(n_[1]) + static_cast<std::size_t>(a)) *
                                  static_cast<std::size_t>(n_[0]);
          for (int r = r0; r <= r1; ++r)
            for (int k = start_[row + static_cast<std::size_t>(r)]; k < start_[row + static_cast<std::size_t>(r) + 1]; ++k)
              f(sorted_[static_cast<std::size_t>(k)]);
        }
    };
    constexpr double pi = std::numbers::pi, two_pi = 2.0 * std::numbers::pi;
    const double h = half(kAzimuth);
    if (!(h < pi)) return visit(0, last);
    const double c = wrap_angle(centre(kAzimuth));  // in (-pi, pi]: the interval lies in (-2 pi, 2 pi)
    double a_lo = c - h, a_hi = c + h;
    if (a_lo > -pi && a_hi <= pi) return visit(clamp(kAzimuth, a_lo), clamp(kAzimuth, a_hi));
    // Crossing the seam: [a_lo, a_hi] is [a_lo + 2 pi, pi] and [-pi, a_hi] (or [a_lo, pi] and
    // [-pi, a_hi - 2 pi]) on the wrapped axis.
    // (A box reaching exactly -pi also holds the points at +pi.)
    if (a_lo <= -pi) a_lo += two_pi;
    else a_hi -= two_pi;
    const int low_end = clamp(kAzimuth, a_hi), high_begin = clamp(kAzimuth, a_lo);
    if (low_end + 1 >= high_begin) return visit(0, last);
    visit(0, low_end);
    visit(high_begin, last);
  }

  int cells() const { return n_[0] * n_[1] * n_[2]; }

 private:
  // A coordinate outside the grid (or an infinite box edge) clamps to the nearest cell; NaN to 0.
  int clamp(int axis, double v) const {
    const double u = (v - lo_(axis)) * inv_cell_(axis);
    const int n = n_[static_cast<std::size_t>(axis)];
    if (!(u > 0.0)) return 0;
    if (!(u < static_cast<double>(n))) return n - 1;
    return std::min(n - 1, static_cast<int>(u));
  }
  int cell_index(const Eigen::Vector3d& p) const {
    const int e = axes_ == 3 ? clamp(2, p(2)) : 0;
    return (e * n_[1] + clamp(kAzimuth, p(kAzimuth))) * n_[0] + clamp(0, p(0));
  }

  int axes_ = 3;
  std::array<int, 3> n_ = {1, 1, 1};
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero(), inv_cell_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> binned_;
  std::vector<int> start_, cell_of_, fill_, sorted_;
};

}  // namespace trackflow::association
