// Purpose: sparse assignment with a private "none" alternative per row, solved exactly cluster by cluster (connected components of the allowed pairs).
#pragma once

#include "assignment/linear_assignment.hpp"
#include "memory/grow.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::assignment {

// Minimises  sum over rows i of ( cost(i, col(i)) if i takes a column, else none_cost(i) )
// over one-to-one choices, where only the pairs added with add() are allowed. This is the
// n x (m + n) problem [C | diag(none)] (off-diagonal "none" entries forbidden) that global
// nearest neighbour association (a track takes a detection or misses), two-point initiation (a
// detection pairs with one of the previous scan or waits) and GOSPA (a truth pairs with a track
// closer than the cut-off or is missed) each solve.
//
// Why clusters: two rows that share no column, directly or through a chain of rows, cannot affect
// each other's choice, because every row always has its private alternative. So the optimum of
// the whole problem is the union of the optima of its connected components (rows and columns
// joined by allowed pairs) — the "clustering" of multi-target tracking (Blackman & Popoli 1999,
// §6.5; Bar-Shalom, Willett & Tian 2011, §8.3). Each component is solved as a small dense
// [C_k | diag(none_k)] problem by LinearAssignment. With gated pairs the components are small, so
// the cost grows with the number of allowed pairs rather than with rows x columns.
//
// Determinism: a component's rows and columns enter its dense matrix in increasing index order,
// whatever the order of the add() calls, so the same set of pairs always gives the same answer.
// Duplicate pairs: the cheaper cost counts.
//
// Storage: members, grown by the largest problem seen; after that a solve allocates nothing.
class SparseAssignment {
 public:
  // Starts a problem of `rows` rows and `cols` columns with no allowed pair.
  void clear(int rows, int cols) {
    if (rows < 0 || cols < 0) throw std::invalid_argument("sparse assignment: negative size");
    rows_ = rows;
    cols_ = cols;
    memory::assign_grown(none_, static_cast<std::size_t>(rows), 0.0);
    entries_.clear();
  }

  // The cost of row i taking no column (finite).
  void set_none_cost(int row, double cost) {
    check_row(row);
    if (!std::isfinite(cost)) throw std::invalid_argument("sparse assignment: a row's 'none' cost must be finite");
    none_[static_cast<std::size_t>(row)] = cost;
  }

  // Allows row i to take column j at `cost` (finite; forbidden pairs are simply not added).
  void add(int row, int col, double cost) {
    check_row(row);
    if (col < 0 || col >= cols_) throw std::invalid_argument("sparse assignment: column out of range");
    if (!std::isfinite(cost)) throw std::invalid_argument("sparse assignment: a pair's cost must be finite");
    entries_.push_back({row, col, cost});
  }

  int rows() const { return rows_; }
  std::size_t pairs() const { return entries_.size(); }
  int clusters() const { return clusters_; }
  int largest_cluster_rows() const { return largest_rows_; }

  // Column of each row, or -1 for its "none"; the view is valid until the next clear() or solve().
  std::span<const int> solve() {
    const auto R = static_cast<std::size_t>(rows_), N = R + static_cast<std::size_t>(cols_);
    memory::assign_grown(column_for_row_, R, -1);
    total_ = 0.0;
    for (std::size_t i = 0; i < R; ++i) total_ += none_[i];
    clusters_ = largest_rows_ = 0;
    if (entries_.empty()) return column_for_row_;
    // Union-find over rows (0..R-1) and columns (R..N-1).
    parent_.resize(N);
    for (std::size_t k = 0; k < N; ++k) parent_[k] = static_cast<int>(k);
    for (const Entry& e : entries_) unite(e.row, static_cast<int>(R) + e.col);
    // Each component's members in increasing index order: a counting sort by root, rows first.
    // Only components holding at least one pair matter; isolated rows keep their "none".
    memory::assign_grown(root_size_, N + 1, 0);
    for (std::size_t k = 0; k < N; ++k) ++root_size_[static_cast<std::size_t>(find(static_cast<int>(k))) + 1];
    for (std::size_t k = 0; k < N; ++k) root_size_[k + 1] += root_size_[k];
    members_.resize(N);
    memory::reserve_grown(fill_, N);
    fill_.assign(root_size_.begin(), root_size_.end() - 1);
    for (std::size_t k = 0; k < N; ++k) {
      const auto r = static_cast<std::size_t>(find(static_cast<int>(k)));
      members_[static_cast<std::size_t>(fill_[r]++)] = static_cast<int>(k);
    }
    // Entries grouped by component (root of their row), also by counting sort.
    memory::assign_grown(entry_start_, N + 1, 0);
    for (const Entry& e : entries_) ++entry_start_[static_cast<std::size_t>(find(e.row)) + 1];
    for (std::size_t k = 0; k < N; ++k) entry_start_[k + 1] += entry_start_[k];
    sorted_entries_.resize(entries_.size());
    fill_.assign(entry_start_.begin(), entry_start_.end() - 1);
    for (const Entry& e : entries_) sorted_entries_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(find(e.row))]++)] = e;
    local_.resize(N);
    for (std::size_t root = 0; root < N; ++root) {
      const int e0 = entry_start_[root], e1 = entry_start_[root + 1];
      if (e0 == e1) continue;
      solve_component(root, e0, e1);
    }
    return column_for_row_;
  }

  // The minimum total of the last solve (sum of the chosen costs and of the "none" costs).
  double total_cost() const { return total_; }

 private:
  struct Entry {
    int row = 0, col = 0;
    double cost = 0.0;
  };

  void check_row(int row) const {
    if (row < 0 || row >= rows_) throw std::invalid_argument("sparse assignment: row out of range");
  }

  int find(int k) {
    while (parent_[static_cast<std::size_t>(k)] != k) {
      parent_[static_cast<std::size_t>(k)] = parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(k)])];
      k = parent_[static_cast<std::size_t>(k)];
    }
    return k;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    // The smaller index becomes the root: the grouping does not depend on the order of add().
    if (a < b) parent_[static_cast<std::size_t>(b)] = a;
    else parent_[static_cast<std::size_t>(a)] = b;
  }

  void solve_component(std::size_t root, int e0, int e1) {
    const int R = rows_;
    // Local indices: rows 0..k-1 and columns 0..c-1, in increasing global order.
    row_ids_.clear();
    col_ids_.clear();
    for (int p = root_size_[root]; p < root_size_[root + 1]; ++p) {
      const int g = members_[static_cast<std::size_t>(p)];
      if (g < R) {
        local_[static_cast<std::size_t>(g)] = static_cast<int>(row_ids_.size());
        row_ids_.push_back(g);
      } else {
        local_[static_cast<std::size_t>(g)] = static_cast<int>(col_ids_.size());
        col_ids_.push_back(g - R);
      }
    }
    const int k = static_cast<int>(row_ids_.size()), c = static_cast<int>(col_ids_.size()), width = c + k;
    ++clusters_;
    largest_rows_ = std::max(largest_rows_, k);
    memory::assign_grown(dense_, static_cast<std::size_t>(k) * static_cast<std::size_t>(width), kInf);
    for (int i = 0; i < k; ++i)
      dense_[static_cast<std::size_t>(i) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c + i)] =
          none_[static_cast<std::size_t>(row_ids_[static_cast<std::size_t>(i)])];
    for (int p = e0; p < e1; ++p) {
      const Entry& e = sorted_entries_[static_cast<std::size_t>(p)];
      double& slot = dense_[static_cast<std::size_t>(local_[static_cast<std::size_t>(e.row)]) * static_cast<std::size_t>(width) +
                            static_cast<std::size_t>(local_[static_cast<std::size_t>(R + e.col)])];
      slot = std::min(slot, e.cost);
    }
    if (k > reserved_rows_ || width > reserved_cols_) {  // doubling: a creeping largest cluster allocates rarely
      reserved_rows_ = std::max(k, 2 * reserved_rows_);
      reserved_cols_ = std::max(width, 2 * reserved_cols_);
      solver_.reserve(reserved_rows_, reserved_cols_);
    }
    const AssignmentResult r = solver_.solve(std::span<const double>(dense_), k, width);
    // Always feasible: every row has its private finite "none".
    for (int i = 0; i < k; ++i) {
      const int col = r.column_for_row[static_cast<std::size_t>(i)];
      const int g = row_ids_[static_cast<std::size_t>(i)];
      if (col >= 0 && col < c) {
        column_for_row_[static_cast<std::size_t>(g)] = col_ids_[static_cast<std::size_t>(col)];
        total_ += dense_[static_cast<std::size_t>(i) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)] -
                  none_[static_cast<std::size_t>(g)];
      }
    }
  }

  static constexpr double kInf = std::numeric_limits<double>::infinity();
  int rows_ = 0, cols_ = 0, clusters_ = 0, largest_rows_ = 0, reserved_rows_ = 0, reserved_cols_ = 0;
  double total_ = 0.0;
  std::vector<double> none_;
  std::vector<Entry> entries_, sorted_entries_;
  std::vector<int> parent_, root_size_, members_, fill_, entry_start_, local_, row_ids_, col_ids_, column_for_row_;
  std::vector<double> dense_;
  LinearAssignment solver_;
};

}  // namespace trackflow::assignment
