// Purpose: rebuilds the cost matrices of make_scipy_cases.py bit for bit (splitmix64), for the SciPy comparison.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace trackflow::assignment::test {

// Steele, Lea and Flood's splitmix64: integer-only, so C++ and Python produce the same stream.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // [0, 1): a 53-bit integer times 2^-53, exact in any IEEE double arithmetic.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

// The recipe of one case: see CASES in make_scipy_cases.py.
struct ScipyCaseRecipe {
  int rows = 0;
  int cols = 0;
  std::uint64_t seed = 0;
  int int_range = 0;  // 0: real costs in [0, 1024); else integers 0 .. int_range - 1
  int forbid_per_mille = 0;
  int hall = 0;  // > 0: rows 0..hall only use columns 0..hall-1
};

// Row-major; per entry one cost draw, then one forbid draw, as make_scipy_cases.py's matrix().
inline std::vector<double> scipy_case_matrix(const ScipyCaseRecipe& r) {
  SplitMix64 rng(r.seed);
  std::vector<double> m(static_cast<std::size_t>(r.rows) * static_cast<std::size_t>(r.cols));
  for (int i = 0; i < r.rows; ++i)
    for (int j = 0; j < r.cols; ++j) {
      const double cost = r.int_range > 0 ? static_cast<double>(rng.next() % static_cast<std::uint64_t>(r.int_range))
                                          : rng.uniform() * 1024.0;
      bool forbidden = rng.next() % 1000 < static_cast<std::uint64_t>(r.forbid_per_mille);
      if (r.hall > 0 && i <= r.hall && j >= r.hall) forbidden = true;
      m[static_cast<std::size_t>(i) * static_cast<std::size_t>(r.cols) + static_cast<std::size_t>(j)] =
          forbidden ? std::numeric_limits<double>::infinity() : cost;
    }
  return m;
}

}  // namespace trackflow::assignment::test
