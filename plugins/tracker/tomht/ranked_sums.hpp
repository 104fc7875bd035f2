// Purpose: the combinations of one entry per ranked list (each list sorted by cost) in order of increasing total cost, generated lazily — the k best joint hypotheses of independent clusters, each cluster's own k best assignments one list.
#pragma once

#include "memory/grow.hpp"

#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <vector>

namespace trackflow::tomht {

// Lists L_0..L_{C-1}, each sorted ascending (L_c[0] its best); a combination picks one index per
// list, costing sum_c L_c[i_c]. next() returns the combinations best first, each exactly once.
//
// Why this is enough for the MHT: the assignment problem of one global hypothesis falls apart into
// clusters of track trees that share gated detections (clustering: Blackman 2004; Cox &
// Hingorani 1996 solve the independent subproblems apart); a joint answer is one answer per cluster and its
// cost is the sum, so the k best joint answers are the k best sums over the clusters' k best lists
// (each cluster ranked by Murty).
//
// Enumeration: the lists with at least two entries are ordered by their gap g = L[1] - L[0]
// ascending. A state is (p, i_0..i_p) with i_q = 0 for q > p (p: the last position moved). The root
// (all best) has one successor, (0, [1]); a state with last position p has at most three:
//   A: i_p + 1;  B: i_{p+1} = 1;  C (when i_p = 1): i_p = 0 and i_{p+1} = 1.
// Every other combination has exactly one predecessor (undo A when i_p > 1; when i_p = 1: undo C if
// i_{p-1} = 0, else undo B), so the states form a tree rooted at the best combination; and every
// successor costs at least its parent (A: the list is sorted; B: a gap >= 0; C: g_{p+1} - g_p >= 0
// by the gap order). Best-first search over that tree (a heap keyed by (cost, creation number))
// therefore pops the combinations in non-decreasing cost, each once, with at most three pushes per
// pop (the scheme of the k smallest sums over sorted lists; cf. Chegireddy & Hamacher 1987 for the
// k-best partition idea). The order among equal costs is the creation order: deterministic.
//
// The lists may be revealed lazily (RankedLists::extend): an entry is asked for only when a
// combination that uses it is about to be queued, so a list produced by an expensive ranking
// (Murty) is computed only as deep as the enumeration goes. The answers do not change.
//
// Storage: member vectors reused across calls; a state keeps its indices 0..p in a pool.
class RankedLists {
 public:
  virtual int lists() const = 0;
  virtual int size(int list) const = 0;  // entries known so far (>= 1)
  virtual double at(int list, int i) const = 0;
  // More entries of `list` (its size grows); false when it has no more.
  virtual bool extend(int /*list*/) { return false; }

 protected:
  ~RankedLists() = default;
};

// Lists given in full (tests, small cases).
class FixedLists final : public RankedLists {
 public:
  void clear() {
    costs_.clear();
    first_.assign(1, 0);
  }
  // Appends a list (ascending; at least one entry).
  void add_list(std::span<const double> costs) {
    if (costs.empty()) throw std::invalid_argument("FixedLists::add_list: an empty list");
    costs_.insert(costs_.end(), costs.begin(), costs.end());
    first_.push_back(static_cast<int>(costs_.size()));
  }
  int lists() const override { return static_cast<int>(first_.size()) - 1; }
  int size(int l) const override { return first_[static_cast<std::size_t>(l) + 1] - first_[static_cast<std::size_t>(l)]; }
  double at(int l, int i) const override { return costs_[static_cast<std::size_t>(first_[static_cast<std::size_t>(l)] + i)]; }

 private:
  std::vector<double> costs_;
  std::vector<int> first_{0};
};

class RankedSums {
 public:
  // Starts the enumeration over src's lists (src must outlive the enumeration).
  void start(RankedLists& src) {
    src_ = &src;
    const int c = src.lists();
    base_ = 0.0;
    moving_.clear();
    for (int l = 0; l < c; ++l) {
      base_ += at(l, 0);
      if (size(l) >= 2 || src.extend(l)) moving_.push_back(l);
    }
    // Ties by list index: a fixed order.
    std::stable_sort(moving_.begin(), moving_.end(),
                     [&](int a, int b) { return at(a, 1) - at(a, 0) < at(b, 1) - at(b, 0); });
    states_.clear();
    pool_.clear();
    heap_.clear();
    memory::assign_grown(index_, static_cast<std::size_t>(c), 0);
    (void)base_;
    push(base_, -1, -1, 0, 0);
  }

  // The next combination (false when all were given); then cost() and index(list).
  bool next() {
    if (heap_.empty()) return false;
    std::pop_heap(heap_.begin(), heap_.end(), later());
    const int id = heap_.back();
    heap_.pop_back();
    const State s = states_[static_cast<std::size_t>(id)];
    cost_ = s.cost;
    std::fill(index_.begin(), index_.end(), 0);
    for (int q = 0; q <= s.p; ++q)
      index_[static_cast<std::size_t>(moving_[static_cast<std::size_t>(q)])] = pool_[static_cast<std::size_t>(s.values + q)];
    const int L = static_cast<int>(moving_.size());
    if (s.p < 0) {
      if (L > 0) push(s.cost + gap(0), id, 0, 1, 0);
      return true;
    }
    const int list = moving_[static_cast<std::size_t>(s.p)];
    const int v = pool_[static_cast<std::size_t>(s.values + s.p)];
    if (v + 1 < size(list) || src_->extend(list)) push(s.cost + at(list, v + 1) - at(list, v), id, s.p, v + 1, 0);  // A
    if (s.p + 1 < L) {
      push(s.cost + gap(s.p + 1), id, s.p + 1, 1, 0);  // B
      if (v == 1) push(s.cost - gap(s.p) + gap(s.p + 1), id, s.p + 1, 1, 1);  // C
    }
    return true;
  }

  double cost() const { return cost_; }
  int index(int list) const { return index_[static_cast<std::size_t>(list)]; }
  std::span<const int> indices() const { return index_; }

 private:
  struct State {
    double cost = 0.0;
    int p = -1;       // last position moved (into moving_), -1 at the root
    int values = 0;   // pool_[values, values + p]: the indices of positions 0..p
  };

  int size(int l) const { return src_->size(l); }
  double at(int l, int i) const { return src_->at(l, i); }
  double gap(int position) const {
    const int l = moving_[static_cast<std::size_t>(position)];
    return at(l, 1) - at(l, 0);
  }

  // A successor of `parent` whose position p takes value v; reset: position p - 1 back to 0 (C).
  void push(double cost, int parent, int p, int v, int reset) {
    State s;
    s.cost = cost;
    s.p = p;
    s.values = static_cast<int>(pool_.size());
    if (p >= 0) {
      const State& from = states_[static_cast<std::size_t>(parent >= 0 ? parent : 0)];
      for (int q = 0; q < p; ++q) {
        const bool copied = parent >= 0 && q <= from.p;
        pool_.push_back(copied ? pool_[static_cast<std::size_t>(from.values + q)] : 0);
      }
      if (reset && p >= 1) pool_[static_cast<std::size_t>(s.values + p - 1)] = 0;
      pool_.push_back(v);
    }
    states_.push_back(s);
    heap_.push_back(static_cast<int>(states_.size()) - 1);
    std::push_heap(heap_.begin(), heap_.end(), later());
  }

  // Heap order: a state comes out after another when it costs more, or as much and was made later.
  struct Later {
    const RankedSums* self;
    bool operator()(int a, int b) const {
      const double ca = self->states_[static_cast<std::size_t>(a)].cost, cb = self->states_[static_cast<std::size_t>(b)].cost;
      return ca > cb || (ca == cb && a > b);
    }
  };
  Later later() const { return Later{this}; }

  RankedLists* src_ = nullptr;
  std::vector<int> moving_;  // the lists with >= 2 entries, by gap ascending
  std::vector<State> states_;
  std::vector<int> pool_, heap_, index_;
  double base_ = 0.0, cost_ = 0.0;
};

}  // namespace trackflow::tomht
