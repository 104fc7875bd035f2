// Purpose: the optimal rectangular assignment by enumerating every one, the tests' reference for small problems.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

namespace trackflow::assignment::test {

struct BruteForceAnswer {
  bool feasible = false;
  double total_cost = std::numeric_limits<double>::infinity();
  long long assignments_tried = 0;  // complete finite assignments seen (for the tests' own checks)
};

// Every injective map of the smaller side into the larger one, by depth-first enumeration; an
// assignment through a +infinity entry does not count. Row-major rows x cols costs.
class BruteForceAssignment {
 public:
  BruteForceAnswer solve(const std::vector<double>& cost, int rows, int cols) {
    cost_ = &cost;
    rows_ = rows;
    cols_ = cols;
    transposed_ = rows > cols;
    small_ = transposed_ ? cols : rows;
    large_ = transposed_ ? rows : cols;
    used_.assign(static_cast<std::size_t>(large_), false);
    answer_ = {};
    if (small_ == 0) return {true, 0.0, 1};
    visit(0, 0.0);
    answer_.feasible = answer_.assignments_tried > 0;
    return answer_;
  }

 private:
  double at(int s, int l) const {
    const int i = transposed_ ? l : s;
    const int j = transposed_ ? s : l;
    return (*cost_)[static_cast<std::size_t>(i) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(j)];
  }

  void visit(int s, double so_far) {
    if (s == small_) {
      ++answer_.assignments_tried;
      if (so_far < answer_.total_cost) answer_.total_cost = so_far;
      return;
    }
    for (int l = 0; l < large_; ++l) {
      if (used_[static_cast<std::size_t>(l)] || std::isinf(at(s, l))) continue;
      used_[static_cast<std::size_t>(l)] = true;
      visit(s + 1, so_far + at(s, l));
      used_[static_cast<std::size_t>(l)] = false;
    }
  }

  const std::vector<double>* cost_ = nullptr;
  int rows_ = 0, cols_ = 0, small_ = 0, large_ = 0;
  bool transposed_ = false;
  std::vector<bool> used_;
  BruteForceAnswer answer_;
};

}  // namespace trackflow::assignment::test
