// Purpose: rectangular linear sum assignment (minimum total cost) by shortest augmenting paths.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::assignment {

// The answer of LinearAssignment::solve. `column_for_row` views the solver's own storage: it is
// valid until the next solve() or reserve() of the same solver.
struct AssignmentResult {
  // True when every row (rows <= cols) or every column (rows > cols) is assigned through finite
  // costs. When false, total_cost is +infinity and every entry of column_for_row is -1: a
  // partial answer would look like a solution to a caller that forgot to check.
  bool feasible = true;
  double total_cost = 0.0;
  std::span<const int> column_for_row;  // assigned column of each row, or -1
};

// Minimises sum_i cost(i, column_for_row[i]) over one-to-one assignments that cover the smaller
// side of an n x m cost matrix (n <= m and n > m both allowed).
//
// Algorithm: the shortest augmenting path method of Jonker and Volgenant in the rectangular form
// of D. F. Crouse, "On implementing 2D rectangular assignment algorithms", IEEE Trans. Aerospace
// and Electronic Systems 52(4):1679-1696, 2016, the pseudocode of pp. 1685-1686
// (the algorithm of SciPy's linear_sum_assignment). Each row of the smaller side is added in
// turn: a Dijkstra search over reduced costs c(i,j) - u(i) - v(j) (non-negative by the dual
// feasibility the method maintains) finds the cheapest alternating path from the new row to a
// free column; the duals are then updated so that every edge of the new matching stays tight,
// and the path is flipped. n rows cost O(n^2 m) in all.
//
// Costs: +infinity forbids a pairing. NaN, -infinity and finite costs of magnitude above 1e300
// are refused with std::invalid_argument: NaN has no order, -infinity makes the minimum
// unbounded, and reduced costs are sums and differences of costs that must not overflow to an
// infinity (which would read as "forbidden") or to NaN.
//
// Ties: the search is a fixed sequence of comparisons over the input, so the same matrix always
// gives the same assignment; among equally short paths the first found column wins, a free one
// before an assigned one (which ends the search earlier).
//
// Storage: the work arrays are members. After reserve(rows, cols) a solve of a problem no larger
// (smaller side and larger side each within the reserved ones) allocates nothing; a larger one
// grows them once. A matrix that is not laid out along the larger side (rows > cols row-major,
// or a column-major Eigen matrix with rows <= cols) is copied once into that layout.
class LinearAssignment {
 public:
  LinearAssignment() = default;
  LinearAssignment(int rows, int cols) { reserve(rows, cols); }

  void reserve(int rows, int cols) {
    check_size(rows, cols);
    const auto small = static_cast<std::size_t>(rows < cols ? rows : cols);
    const auto large = static_cast<std::size_t>(rows < cols ? cols : rows);
    const auto all = static_cast<std::size_t>(rows > cols ? rows : cols);
    dual_small_.reserve(small);
    large_for_small_.reserve(small);
    visited_small_.reserve(small);
    dual_large_.reserve(large);
    small_for_large_.reserve(large);
    path_small_.reserve(large);
    distance_.reserve(large);
    unvisited_large_.reserve(large);
    visited_large_.reserve(large);
    column_for_row_.reserve(all);
    contiguous_.reserve(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  }

  // Row-major: cost(i, j) = cost[i * cols + j].
  AssignmentResult solve(std::span<const double> cost, int rows, int cols) {
    check_size(rows, cols);
    if (cost.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols))
      throw std::invalid_argument("linear assignment: cost has " + std::to_string(cost.size()) + " entries, not " +
                                  std::to_string(rows) + " x " + std::to_string(cols));
    return solve_strided(cost.data(), rows, cols, cols, 1);
  }

  // Any Eigen matrix expression with direct access (column-major MatrixXd, a row-major map, a
  // block), read through its strides.
  template <typename Derived>
  AssignmentResult solve(const Eigen::DenseBase<Derived>& cost) {
    const Derived& m = cost.derived();
    check_size(static_cast<long long>(m.rows()), static_cast<long long>(m.cols()));
    return solve_strided(m.data(), static_cast<int>(m.rows()), static_cast<int>(m.cols()),
                         static_cast<std::ptrdiff_t>(m.rowStride()), static_cast<std::ptrdiff_t>(m.colStride()));
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr double kLargestCost = 1e300;

  static void check_size(long long rows, long long cols) {
    if (rows < 0 || cols < 0)
      throw std::invalid_argument("linear assignment: negative size " + std::to_string(rows) + " x " +
                                  std::to_string(cols));
    if (rows > std::numeric_limits<int>::max() || cols > std::numeric_limits<int>::max())
      throw std::invalid_argument("linear assignment: size beyond int range");
  }

  // cost(i, j) = data[i * row_stride + j * col_stride]. The search always runs from the smaller
  // side ("small": the rows, or the columns when rows > cols) over the larger one.
  AssignmentResult solve_strided(const double* data, int rows, int cols, std::ptrdiff_t row_stride,
                                 std::ptrdiff_t col_stride) {
    check_entries(data, rows, cols, row_stride, col_stride);
    const bool transposed = rows > cols;
    const int small = transposed ? cols : rows;
    const int large = transposed ? rows : cols;
    std::ptrdiff_t small_stride = transposed ? col_stride : row_stride;
    std::ptrdiff_t large_stride = transposed ? row_stride : col_stride;
    if (large_stride != 1 && small > 0) {
      // The search reads one small-side line at a time along the large side: lay the matrix out
      // that way once (O(nm) against the search's O(n^2 m)) rather than stride through memory.
      contiguous_.resize(static_cast<std::size_t>(small) * static_cast<std::size_t>(large));
      for (int a = 0; a < small; ++a)
        for (int b = 0; b < large; ++b)
          contiguous_[static_cast<std::size_t>(a) * static_cast<std::size_t>(large) + static_cast<std::size_t>(b)] =
              data[a * small_stride + b * large_stride];
      data = contiguous_.data();
      small_stride = large;
      large_stride = 1;
    }

    column_for_row_.assign(static_cast<std::size_t>(rows), -1);
    if (small == 0) return {true, 0.0, column_for_row_};

    dual_small_.assign(static_cast<std::size_t>(small), 0.0);
    large_for_small_.assign(static_cast<std::size_t>(small), -1);
    visited_small_.resize(static_cast<std::size_t>(small));
    dual_large_.assign(static_cast<std::size_t>(large), 0.0);
    small_for_large_.assign(static_cast<std::size_t>(large), -1);
    path_small_.resize(static_cast<std::size_t>(large));
    distance_.resize(static_cast<std::size_t>(large));
    unvisited_large_.resize(static_cast<std::size_t>(large));
    visited_large_.resize(static_cast<std::size_t>(large));

    for (int start = 0; start < small; ++start) {
      const int sink = shortest_augmenting_path(data, start, large, small_stride, large_stride);
      if (sink < 0) {
        // No alternating path of finite cost reaches a free column, so no assignment covers the
        // small-side lines 0..start together (its symmetric difference with the current matching
        // would contain such a path).
        column_for_row_.assign(static_cast<std::size_t>(rows), -1);
        return {false, kInf, column_for_row_};
      }
      augment(start, sink);
    }

    double total = 0.0;
    for (int s = 0; s < small; ++s) {
      const int l = large_for_small_[static_cast<std::size_t>(s)];
      total += data[s * small_stride + l * large_stride];
      if (transposed)
        column_for_row_[static_cast<std::size_t>(l)] = s;
      else
        column_for_row_[static_cast<std::size_t>(s)] = l;
    }
    return {true, total, column_for_row_};
  }

  static void check_entries(const double* data, int rows, int cols, std::ptrdiff_t row_stride,
                            std::ptrdiff_t col_stride) {
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) {
        const double c = data[i * row_stride + j * col_stride];
        if (c == kInf || std::abs(c) <= kLargestCost) continue;
        const std::string what = std::isnan(c) ? "NaN" : c == -kInf ? "-infinity" : std::to_string(c);
        throw std::invalid_argument("linear assignment: cost(" + std::to_string(i) + ", " + std::to_string(j) +
                                    ") is " + what + "; costs must be within +-1e300 or +infinity (forbidden)");
      }
  }

  // Dijkstra over reduced costs from the free row `start`; ends at the first free column it
  // settles (returned), or returns -1 when every reachable column has infinite distance. Leaves
  // the duals updated so that the path's edges and the matching's edges are tight.
  int shortest_augmenting_path(const double* data, int start, int large, std::ptrdiff_t small_stride,
                               std::ptrdiff_t large_stride) {
    for (int l = 0; l < large; ++l) unvisited_large_[static_cast<std::size_t>(l)] = l;
    std::fill(distance_.begin(), distance_.end(), kInf);
    std::fill(visited_small_.begin(), visited_small_.end(), false);
    std::fill(visited_large_.begin(), visited_large_.end(), false);

    int unvisited = large;
    int s = start;
    int sink = -1;
    double settled = 0.0;  // distance of the last settled column (0 for the start row)
    while (sink < 0) {
      visited_small_[static_cast<std::size_t>(s)] = true;
      const double* row = data + s * small_stride;
      const double row_dual = dual_small_[static_cast<std::size_t>(s)];
      double lowest = kInf;
      int lowest_at = -1;
      for (int k = 0; k < unvisited; ++k) {
        const int l = unvisited_large_[static_cast<std::size_t>(k)];
        const auto lu = static_cast<std::size_t>(l);
        // +infinity costs give +infinity here and never relax a distance.
        const double through_s = settled + row[l * large_stride] - row_dual - dual_large_[lu];
        if (through_s < distance_[lu]) {
          path_small_[lu] = s;
          distance_[lu] = through_s;
        }
        if (distance_[lu] < lowest || (distance_[lu] == lowest && lowest_at >= 0 && small_for_large_[lu] < 0 &&
                                       small_for_large_[static_cast<std::size_t>(
                                           unvisited_large_[static_cast<std::size_t>(lowest_at)])] >= 0)) {
          lowest = distance_[lu];
          lowest_at = k;
        }
      }
      if (lowest == kInf) return -1;
      settled = lowest;
      const int l = unvisited_large_[static_cast<std::size_t>(lowest_at)];
      visited_large_[static_cast<std::size_t>(l)] = true;
      unvisited_large_[static_cast<std::size_t>(lowest_at)] = unvisited_large_[static_cast<std::size_t>(--unvisited)];
      if (small_for_large_[static_cast<std::size_t>(l)] < 0)
        sink = l;
      else
        s = small_for_large_[static_cast<std::size_t>(l)];
    }

    // Dual update (Crouse, pp. 1685-1686): rows and columns settled before the sink move by how much
    // shorter their path was than the sink's, which keeps reduced costs >= 0 and makes the
    // augmenting path tight.
    dual_small_[static_cast<std::size_t>(start)] += settled;
    const int small = static_cast<int>(dual_small_.size());
    for (int r = 0; r < small; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      if (!visited_small_[ru] || r == start) continue;
      dual_small_[ru] += settled - distance_[static_cast<std::size_t>(large_for_small_[ru])];
    }
    for (int c = 0; c < large; ++c) {
      const auto cu = static_cast<std::size_t>(c);
      if (visited_large_[cu]) dual_large_[cu] -= settled - distance_[cu];
    }
    return sink;
  }

  // Flips the alternating path that ends at the free column `sink` back to `start`.
  void augment(int start, int sink) {
    int l = sink;
    while (true) {
      const int s = path_small_[static_cast<std::size_t>(l)];
      small_for_large_[static_cast<std::size_t>(l)] = s;
      const int previous = large_for_small_[static_cast<std::size_t>(s)];
      large_for_small_[static_cast<std::size_t>(s)] = l;
      if (s == start) break;
      l = previous;
    }
  }

  // "small" indexes the side that is searched from (the rows, or the columns when rows > cols).
  std::vector<double> dual_small_;
  std::vector<int> large_for_small_;
  std::vector<char> visited_small_;
  std::vector<double> dual_large_;
  std::vector<int> small_for_large_;
  std::vector<int> path_small_;  // the small-side node before each large-side node on its path
  std::vector<double> distance_;
  std::vector<int> unvisited_large_;
  std::vector<char> visited_large_;
  std::vector<int> column_for_row_;
  std::vector<double> contiguous_;  // the costs small-side-major, when the input is not already
};

}  // namespace trackflow::assignment
