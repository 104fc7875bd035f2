// Purpose: the k lowest-cost rectangular assignments (k-best 2-D assignment) by Murty's partitioning over LinearAssignment.
#pragma once

#include "assignment/linear_assignment.hpp"
#include "memory/grow.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::assignment {

// One answer of KBestAssignment::solve. `column_for_row` views the solver's storage: valid until
// the next solve() or reserve() of the same solver.
struct RankedAssignment {
  double total_cost = 0.0;              // sum of the chosen entries, rows (or columns) in index order
  std::span<const int> column_for_row;  // assigned column of each row, or -1
};

// The k assignments of least total cost of an n x m cost matrix, with LinearAssignment's
// semantics: one-to-one, covering the smaller side; +infinity forbids a pairing; NaN, -infinity
// and finite magnitudes above 1e300 are refused with std::invalid_argument. Answers come sorted
// by total cost ascending and are pairwise distinct; fewer than k come back when fewer feasible
// assignments exist (none for an infeasible problem; one, the empty one, for a 0 x m matrix).
//
// Algorithm: K. G. Murty, "An algorithm for ranking all the assignments in order of increasing
// cost", Operations Research 16(3):682-687, 1968 (doi:10.1287/opre.16.3.682), in the form of
// M. L. Miller, H. S. Stone and I. J. Cox, "Optimizing Murty's ranked assignment method", IEEE
// Trans. Aerospace and Electronic Systems 33(3):851-862, 1997 (doi:10.1109/7.599256). Work on the
// smaller side ("lines", the rows or the columns when rows > cols), so that an assignment is a
// map line -> large-side index. A subproblem P is the set of assignments that contain a set I of
// required pairs and avoid a set O of forbidden ones. Let A = {(s_1, l_1), ..., (s_t, l_t)} be
// the optimum of P without the pairs of I (its free lines s_1 < ... < s_t). Then
//     P \ {A} = P_1 u ... u P_t  (disjoint),  P_j: required I u {(s_1,l_1), ..., (s_{j-1},l_{j-1})},
//                                               forbidden O u {(s_j, l_j)},
// because an assignment B of P other than A has a first free line s_j at which it differs from
// A, which puts B in P_j and in no other child. Start from P_0 = all assignments; keep a
// priority queue of subproblems keyed by their optimum; pop the least, report its optimum,
// replace it by its P_1..P_t (each solved, the infeasible dropped). The queue's subproblems
// always partition the assignments not yet reported, so the least key is the best of those: the
// r-th pop is the r-th best assignment, and none is reported twice. A subproblem is solved by LinearAssignment
// on the matrix of its free lines x free large-side indices (those not taken by a required pair),
// forbidden pairs set to +infinity. Required pairs on lines already fixed make the forbidden
// pairs of those lines irrelevant; they are dropped from the children.
//
// Tracking use (k-best JPDA hypotheses, track-oriented MHT): n tracks x (m detections + n miss
// columns), track i's miss cost at column m + i and +infinity at the other miss columns, so that
// every answer is a joint hypothesis (a column >= m is track i's miss) and the k answers are the
// k most likely ones when costs are negative log-likelihoods.
//
// Not done: Miller, Stone & Cox's optimisations (inheriting the parent's duals and partial
// matching so that a child needs one augmenting path, O(n m) instead of O(n^2 m); lower bounds
// to solve children lazily; an optimised partition order). They change speed, not answers.
//
// Complexity (n the smaller, m the larger side): a popped subproblem with f free lines has f
// children, each solved from scratch in O(f^2 m) by LinearAssignment (plus O(n m) to lay out
// its matrix): O(k n^3 m) time for k answers, plus O(k n log(k n)) for the heap. Storage: up to
// 1 + (k - 1) n subproblems of O(n + d) integers each (d: forbidden pairs, at most the depth).
//
// Ties and determinism: the queue pops the least (total cost, creation number) — a strict order,
// so the pop sequence does not depend on the heap's layout. Children are created in the fixed
// order of the partition (a parent's free lines in increasing index), and each is solved by
// LinearAssignment, whose own ties are broken deterministically. So the same input always gives
// the same output, and (costs summing exactly, e.g. integers) solve(k) is the first k answers of
// solve(k') for k <= k'. Which of several equal-cost assignments falls inside the cut at k is
// this search's choice, not a canonical one (not, say, lexicographic). Totals are recomputed from
// the chosen entries in line order; when rounding makes a child's total a few ulps below an
// answer already found, it is moved in front (an insertion), so the output is sorted exactly.
//
// resume(k) after solve(): the same search continued to k answers (the last answer's subproblem
// partitioned then), identical to solve(k) and solving nothing twice.
//
// Storage: all work arrays are members (vectors cleared, never shrunk; the queue is a heap over
// a vector). Once a solver has seen a problem as large, with as many answers and subproblems, a
// solve allocates nothing.
class KBestAssignment {
 public:
  KBestAssignment() = default;
  KBestAssignment(int rows, int cols, int k) { reserve(rows, cols, k); }

  // Storage for k answers of a rows x cols problem at the worst case of 1 + k n subproblems
  // (n = min(rows, cols)); far fewer occur in practice (fixed lines have no children), and
  // whatever a solve still needs grows geometrically.
  void reserve(int rows, int cols, int k) {
    check_k(k);
    solver_.reserve(rows, cols);
    const auto small = static_cast<std::size_t>(std::min(rows, cols));
    const auto large = static_cast<std::size_t>(std::max(rows, cols));
    const auto answers = static_cast<std::size_t>(k);
    const std::size_t nodes = 1 + answers * std::max<std::size_t>(small, 1);
    work_.reserve(small * large);
    sub_.reserve(small * large);
    nodes_.reserve(nodes);
    heap_.reserve(nodes);
    line_pool_.reserve(2 * nodes * small);
    forbid_pool_.reserve(2 * nodes * small);
    answer_lines_.reserve(answers * small);
    answer_costs_.reserve(answers);
    order_.reserve(answers);
    columns_.reserve(answers * static_cast<std::size_t>(rows));
    results_.reserve(answers);
    for (std::vector<int>* v : {&solution_, &fixed_, &parent_solution_, &parent_fixed_, &sub_line_of_, &sub_rows_})
      v->reserve(small);
    for (std::vector<int>* v : {&sub_index_of_large_, &sub_cols_}) v->reserve(large);
    parent_forbid_.reserve(2 * small);
    parent_forbid_all_.reserve(2 * small);
  }

  // Row-major: cost(i, j) = cost[i * cols + j]. k >= 0 (k = 0: no answers, input still checked).
  std::span<const RankedAssignment> solve(std::span<const double> cost, int rows, int cols, int k) {
    check_k(k);
    const AssignmentResult root = solver_.solve(cost, rows, cols);  // checks sizes and entries
    return run(cost.data(), rows, cols, cols, 1, root, k);
  }

  // Any Eigen matrix expression with direct access, read through its strides.
  template <typename Derived>
  std::span<const RankedAssignment> solve(const Eigen::DenseBase<Derived>& cost, int k) {
    check_k(k);
    const Derived& m = cost.derived();
    const AssignmentResult root = solver_.solve(m);
    return run(m.data(), static_cast<int>(m.rows()), static_cast<int>(m.cols()),
               static_cast<std::ptrdiff_t>(m.rowStride()), static_cast<std::ptrdiff_t>(m.colStride()), root, k);
  }

  // More answers of the last solve(): the first k of the same problem, exactly as solve(..., k)
  // gives them (the search goes on where it stopped: the subproblem of the last answer is
  // partitioned now, and nothing is solved twice). For a caller that learns only while reading
  // the answers how many it needs (the track-oriented MHT's lazily ranked clusters). Views as for
  // solve(); k below the answers found gives the first k.
  std::span<const RankedAssignment> resume(int k) {
    check_k(k);
    results_.clear();
    if (!searched_) return results_;
    return search(k);
  }

  // Subproblems handed to LinearAssignment by the last solve, the root included (for tests and
  // cost accounting).
  long long subproblems_solved() const { return subproblems_solved_; }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  // A subproblem of the partition: its optimum (cost, line -> large map) and its constraints.
  struct Node {
    double cost = 0.0;
    std::size_t lines = 0;   // line_pool_[lines, +n): optimum; [lines + n, +n): required large or -1
    std::size_t forbid = 0;  // forbid_pool_[forbid, +2 * forbid_count): (line, large) pairs
    int forbid_count = 0;
  };

  static void check_k(long long k) {
    if (k < 0) throw std::invalid_argument("k-best assignment: k = " + std::to_string(k) + " is negative");
  }

  // Heap order: a node comes out after another when it costs more, or as much and was made later.
  auto later() const {
    return [this](int a, int b) {
      const double ca = nodes_[static_cast<std::size_t>(a)].cost, cb = nodes_[static_cast<std::size_t>(b)].cost;
      return ca > cb || (ca == cb && a > b);
    };
  }

  std::span<const RankedAssignment> run(const double* data, int rows, int cols, std::ptrdiff_t row_stride,
                                        std::ptrdiff_t col_stride, const AssignmentResult& root, int k) {
    transposed_ = rows > cols;
    small_ = transposed_ ? cols : rows;
    large_ = transposed_ ? rows : cols;
    const auto n = static_cast<std::size_t>(small_);
    subproblems_solved_ = 1;
    nodes_.clear();
    heap_.clear();
    line_pool_.clear();
    forbid_pool_.clear();
    answer_lines_.clear();
    answer_costs_.clear();
    order_.clear();
    columns_.clear();
    results_.clear();
    searched_ = false;
    pending_ = -1;
    rows_ = rows;
    if (!root.feasible) return {};

    // The costs line-major (line s, large index l at work_[s * large_ + l]), read by every
    // subproblem; the root's answer as a line -> large map.
    const std::ptrdiff_t line_stride = transposed_ ? col_stride : row_stride;
    const std::ptrdiff_t large_stride = transposed_ ? row_stride : col_stride;
    memory::assign_grown(work_, n * static_cast<std::size_t>(large_), 0.0);
    for (int s = 0; s < small_; ++s)
      for (int l = 0; l < large_; ++l) work_[at(s, l)] = data[s * line_stride + l * large_stride];
    memory::assign_grown(solution_, n, -1);
    for (int i = 0; i < rows; ++i) {
      const int j = root.column_for_row[static_cast<std::size_t>(i)];
      if (j < 0) continue;
      if (transposed_)
        solution_[static_cast<std::size_t>(j)] = i;
      else
        solution_[static_cast<std::size_t>(i)] = j;
    }
    memory::assign_grown(fixed_, n, -1);
    parent_forbid_.clear();
    push_node();
    searched_ = true;
    return search(k);
  }

  // Pops answers until k are found (or none is left), then lays out the first k.
  std::span<const RankedAssignment> search(int k) {
    const auto n = static_cast<std::size_t>(small_);
    (void)n;
    if (pending_ >= 0 && static_cast<int>(answer_costs_.size()) < k) {
      partition(pending_);  // the last answer's children: what a longer search would have made
      pending_ = -1;
    }
    while (!heap_.empty() && static_cast<int>(answer_costs_.size()) < k) {
      std::pop_heap(heap_.begin(), heap_.end(), later());
      const int id = heap_.back();
      heap_.pop_back();
      record_answer(nodes_[static_cast<std::size_t>(id)]);
      if (static_cast<int>(answer_costs_.size()) < k)
        partition(id);
      else
        pending_ = id;
    }

    // Rows' columns of each answer in sorted order, then the views (after all growth).
    columns_.clear();
    results_.clear();
    const auto r = static_cast<std::size_t>(rows_);
    const std::size_t count = std::min(order_.size(), static_cast<std::size_t>(k));
    for (std::size_t q = 0; q < count; ++q) {
      const int a = order_[q];
      const std::size_t base = columns_.size();
      columns_.resize(base + r, -1);
      for (int s = 0; s < small_; ++s) {
        const int l = answer_lines_[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(s)];
        if (transposed_)
          columns_[base + static_cast<std::size_t>(l)] = s;
        else
          columns_[base + static_cast<std::size_t>(s)] = l;
      }
    }
    for (std::size_t q = 0; q < count; ++q)
      results_.push_back({answer_costs_[static_cast<std::size_t>(order_[q])],
                          std::span<const int>(columns_.data() + q * r, r)});
    return results_;
  }

  std::size_t at(int s, int l) const {
    return static_cast<std::size_t>(s) * static_cast<std::size_t>(large_) + static_cast<std::size_t>(l);
  }

  // Stores solution_ / fixed_ / parent_forbid_ as a new subproblem and queues it.
  void push_node() {
    Node node;
    node.lines = line_pool_.size();
    node.forbid = forbid_pool_.size();
    node.forbid_count = static_cast<int>(parent_forbid_.size() / 2);
    // The total in line order, from the entries themselves (also the order LinearAssignment sums in).
    for (int s = 0; s < small_; ++s) node.cost += work_[at(s, solution_[static_cast<std::size_t>(s)])];
    line_pool_.insert(line_pool_.end(), solution_.begin(), solution_.end());
    line_pool_.insert(line_pool_.end(), fixed_.begin(), fixed_.end());
    forbid_pool_.insert(forbid_pool_.end(), parent_forbid_.begin(), parent_forbid_.end());
    nodes_.push_back(node);
    heap_.push_back(static_cast<int>(nodes_.size()) - 1);
    std::push_heap(heap_.begin(), heap_.end(), later());
  }

  void record_answer(const Node& node) {
    const auto n = static_cast<std::size_t>(small_);
    answer_lines_.insert(answer_lines_.end(), line_pool_.begin() + static_cast<std::ptrdiff_t>(node.lines),
                         line_pool_.begin() + static_cast<std::ptrdiff_t>(node.lines + n));
    answer_costs_.push_back(node.cost);
    // Insertion into the sorted order: moves only past answers strictly dearer, which happens
    // only through rounding (a child's exact optimum is never below its parent's).
    const int a = static_cast<int>(answer_costs_.size()) - 1;
    order_.push_back(a);
    for (std::size_t q = order_.size() - 1;
         q > 0 && answer_costs_[static_cast<std::size_t>(order_[q - 1])] > node.cost; --q)
      std::swap(order_[q - 1], order_[q]);
  }

  // Murty's partition of the popped subproblem `id` into its children P_1..P_t (see above).
  void partition(int id) {
    const Node parent = nodes_[static_cast<std::size_t>(id)];  // a copy: nodes_ grows below
    const auto n = static_cast<std::size_t>(small_);
    const auto lines = static_cast<std::ptrdiff_t>(parent.lines);
    parent_solution_.assign(line_pool_.begin() + lines, line_pool_.begin() + lines + static_cast<std::ptrdiff_t>(n));
    parent_fixed_.assign(line_pool_.begin() + lines + static_cast<std::ptrdiff_t>(n),
                         line_pool_.begin() + lines + static_cast<std::ptrdiff_t>(2 * n));
    const auto f0 = static_cast<std::ptrdiff_t>(parent.forbid);
    parent_forbid_all_.assign(forbid_pool_.begin() + f0, forbid_pool_.begin() + f0 + 2 * parent.forbid_count);

    fixed_.assign(parent_fixed_.begin(), parent_fixed_.end());
    for (int s = 0; s < small_; ++s) {
      if (parent_fixed_[static_cast<std::size_t>(s)] >= 0) continue;
      const int l = parent_solution_[static_cast<std::size_t>(s)];
      // Child P_j for free line s: fixed_ holds I plus the earlier free lines' pairs; forbidden:
      // the parent's pairs on lines still free, and (s, l).
      parent_forbid_.clear();
      for (std::size_t p = 0; p < parent_forbid_all_.size(); p += 2)
        if (fixed_[static_cast<std::size_t>(parent_forbid_all_[p])] < 0) {
          parent_forbid_.push_back(parent_forbid_all_[p]);
          parent_forbid_.push_back(parent_forbid_all_[p + 1]);
        }
      parent_forbid_.push_back(s);
      parent_forbid_.push_back(l);
      if (solve_child()) push_node();
      fixed_[static_cast<std::size_t>(s)] = l;  // required in the later children
    }
  }

  // Solves the subproblem fixed_ / parent_forbid_ into solution_; false when infeasible.
  bool solve_child() {
    sub_rows_.clear();
    sub_cols_.clear();
    memory::assign_grown(sub_index_of_large_, static_cast<std::size_t>(large_), 0);
    memory::assign_grown(sub_line_of_, static_cast<std::size_t>(small_), -1);
    for (int s = 0; s < small_; ++s) {
      const int l = fixed_[static_cast<std::size_t>(s)];
      if (l >= 0)
        sub_index_of_large_[static_cast<std::size_t>(l)] = -1;  // taken by a required pair
      else {
        sub_line_of_[static_cast<std::size_t>(s)] = static_cast<int>(sub_rows_.size());
        sub_rows_.push_back(s);
      }
    }
    for (int l = 0; l < large_; ++l) {
      if (sub_index_of_large_[static_cast<std::size_t>(l)] < 0) continue;
      sub_index_of_large_[static_cast<std::size_t>(l)] = static_cast<int>(sub_cols_.size());
      sub_cols_.push_back(l);
    }
    const int fr = static_cast<int>(sub_rows_.size());
    const int fc = static_cast<int>(sub_cols_.size());
    memory::assign_grown(sub_, static_cast<std::size_t>(fr) * static_cast<std::size_t>(fc), 0.0);
    for (int a = 0; a < fr; ++a)
      for (int b = 0; b < fc; ++b)
        sub_[static_cast<std::size_t>(a) * static_cast<std::size_t>(fc) + static_cast<std::size_t>(b)] =
            work_[at(sub_rows_[static_cast<std::size_t>(a)], sub_cols_[static_cast<std::size_t>(b)])];
    for (std::size_t p = 0; p < parent_forbid_.size(); p += 2) {
      // Every kept forbidden pair is on a free line; its large index may be taken by a required
      // pair, which forbids it anyway.
      const int a = sub_line_of_[static_cast<std::size_t>(parent_forbid_[p])];
      const int b = sub_index_of_large_[static_cast<std::size_t>(parent_forbid_[p + 1])];
      if (b >= 0) sub_[static_cast<std::size_t>(a) * static_cast<std::size_t>(fc) + static_cast<std::size_t>(b)] = kInf;
    }
    ++subproblems_solved_;
    const AssignmentResult r = solver_.solve(sub_, fr, fc);  // fr <= fc: rows are the lines
    if (!r.feasible) return false;
    for (int s = 0; s < small_; ++s) {
      const int l = fixed_[static_cast<std::size_t>(s)];
      solution_[static_cast<std::size_t>(s)] =
          l >= 0 ? l
                 : sub_cols_[static_cast<std::size_t>(
                       r.column_for_row[static_cast<std::size_t>(sub_line_of_[static_cast<std::size_t>(s)])])];
    }
    return true;
  }

  LinearAssignment solver_;
  int small_ = 0, large_ = 0, rows_ = 0;
  bool searched_ = false;  // a search to resume: the last solve's queue and answers
  int pending_ = -1;       // the last answer's node, not yet partitioned
  bool transposed_ = false;
  long long subproblems_solved_ = 0;
  std::vector<double> work_;  // costs line-major
  std::vector<double> sub_;   // a subproblem's matrix
  std::vector<Node> nodes_;
  std::vector<int> heap_;  // node ids, a min-heap by (cost, id)
  std::vector<int> line_pool_, forbid_pool_;
  std::vector<int> solution_, fixed_, parent_solution_, parent_fixed_, parent_forbid_, parent_forbid_all_;
  std::vector<int> sub_line_of_, sub_index_of_large_, sub_rows_, sub_cols_;
  std::vector<int> answer_lines_;  // answers' line -> large maps, in pop order
  std::vector<double> answer_costs_;
  std::vector<int> order_;    // answer indices sorted by total cost
  std::vector<int> columns_;  // answers' column_for_row, in sorted order
  std::vector<RankedAssignment> results_;
};

}  // namespace trackflow::assignment
