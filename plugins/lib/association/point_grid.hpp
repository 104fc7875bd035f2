// Purpose: a uniform 2-D grid over points (detection positions) that lists the candidates near a box: the coarse spatial pre-gate before an exact gate test.
#pragma once

#include "memory/grow.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace trackflow::association {

// Points are binned by (x, y) into square cells over their bounding box. for_each_candidate(lo,
// hi, f) calls f(point index) for every point in a cell that overlaps the box [lo, hi]: a superset
// of the points inside the box, which the caller then tests exactly (a chi-square gate, a pairing
// distance). Within a query the order is fixed — cells row by row, points in index order within a
// cell — so results never depend on anything but the input.
//
// Cost: build O(points + cells); a query O(cells overlapped + candidates). The cell count is kept
// at most about 2 x points + 16 (the cell side grows when the points are spread wide), so a box
// larger than the whole grid costs O(points), as testing every point would.
//
// Storage: members, grown by the largest input seen; after that build() allocates nothing.
class PointGrid {
 public:
  // `cell`: the wanted side of a cell (e.g. the typical gate width); <= 0 or non-finite: one cell.
  void build(std::span<const Eigen::Vector2d> points, double cell) {
    const std::size_t n = points.size();
    nx_ = ny_ = 1;
    lo_ = Eigen::Vector2d::Zero();
    inv_cell_ = 0.0;
    if (n > 0) {
      Eigen::Vector2d lo = points[0], hi = points[0];
      for (const auto& p : points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      const Eigen::Vector2d extent = hi - lo;
      lo_ = lo;
      if (std::isfinite(cell) && cell > 0.0 && extent.allFinite()) {
        const double max_cells = 2.0 * static_cast<double>(n) + 16.0;
        double side = cell;
        // Grow the side until the grid has at most max_cells cells.
        while ((std::floor(extent.x() / side) + 1.0) * (std::floor(extent.y() / side) + 1.0) > max_cells) side *= 1.5;
        inv_cell_ = 1.0 / side;
        nx_ = static_cast<int>(std::floor(extent.x() * inv_cell_)) + 1;
        ny_ = static_cast<int>(std::floor(extent.y() * inv_cell_)) + 1;
      }
    }
    const auto cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
    memory::assign_grown(start_, cells + 1, 0);
    cell_of_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = static_cast<std::size_t>(cell_index(points[i]));
      cell_of_[i] = static_cast<int>(c);
      ++start_[c + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    memory::reserve_grown(fill_, cells);
    fill_.assign(start_.begin(), start_.end() - 1);
    sorted_.resize(n);
    for (std::size_t i = 0; i < n; ++i) sorted_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(cell_of_[i])]++)] = static_cast<int>(i);
  }

  template <class F>
  void for_each_candidate(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, F&& f) const {
    if (sorted_.empty()) return;
    const int x0 = clamp_x(lo.x()), x1 = clamp_x(hi.x()), y0 = clamp_y(lo.y()), y1 = clamp_y(hi.y());
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const auto c = static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x);
        for (int k = start_[c]; k < start_[c + 1]; ++k) f(sorted_[static_cast<std::size_t>(k)]);
      }
  }

  int cells() const { return nx_ * ny_; }

 private:
  int clamp_x(double x) const { return clamp_cell((x - lo_.x()) * inv_cell_, nx_); }
  int clamp_y(double y) const { return clamp_cell((y - lo_.y()) * inv_cell_, ny_); }
  // A coordinate outside the grid (or NaN, or an infinite box edge) clamps to the nearest cell.
  static int clamp_cell(double u, int n) {
    if (!(u > 0.0)) return 0;
    if (!(u < static_cast<double>(n))) return n - 1;
    return std::min(n - 1, static_cast<int>(u));
  }
  int cell_index(const Eigen::Vector2d& p) const { return clamp_y(p.y()) * nx_ + clamp_x(p.x()); }

  int nx_ = 1, ny_ = 1;
  double inv_cell_ = 0.0;
  Eigen::Vector2d lo_ = Eigen::Vector2d::Zero();
  std::vector<int> start_, cell_of_, fill_, sorted_;
};

}  // namespace trackflow::association
