// Purpose: SparseAssignment (clustered, private "none" per row) against the dense [C | diag(none)] problem solved by LinearAssignment and against brute force; order independence; duplicates; bad input.
#include "assignment/sparse_assignment.hpp"

#include "brute_force_assignment.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

using trackflow::assignment::LinearAssignment;
using trackflow::assignment::SparseAssignment;
using trackflow::assignment::test::BruteForceAssignment;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Problem {
  int rows = 0, cols = 0;
  std::vector<double> none;
  std::vector<std::tuple<int, int, double>> pairs;
};

Problem random_problem(std::mt19937_64& rng, int max_rows, int max_cols, bool integer) {
  std::uniform_int_distribution<int> nr(0, max_rows), nc(0, max_cols);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Problem p;
  p.rows = nr(rng);
  p.cols = nc(rng);
  const double density = u(rng);
  auto value = [&] { return integer ? std::floor(10.0 * u(rng)) - 3.0 : 10.0 * u(rng) - 3.0; };
  for (int i = 0; i < p.rows; ++i) p.none.push_back(value());
  for (int i = 0; i < p.rows; ++i)
    for (int j = 0; j < p.cols; ++j)
      if (u(rng) < density) p.pairs.emplace_back(i, j, value());
  return p;
}

// The same problem as one dense n x (m + n) matrix.
std::vector<double> dense(const Problem& p) {
  const int w = p.cols + p.rows;
  std::vector<double> c(static_cast<std::size_t>(p.rows) * static_cast<std::size_t>(w), kInf);
  for (int i = 0; i < p.rows; ++i) c[static_cast<std::size_t>(i * w + p.cols + i)] = p.none[static_cast<std::size_t>(i)];
  for (const auto& [i, j, v] : p.pairs) {
    double& s = c[static_cast<std::size_t>(i * w + j)];
    s = std::min(s, v);
  }
  return c;
}

void load(SparseAssignment& s, const Problem& p) {
  s.clear(p.rows, p.cols);
  for (int i = 0; i < p.rows; ++i) s.set_none_cost(i, p.none[static_cast<std::size_t>(i)]);
  for (const auto& [i, j, v] : p.pairs) s.add(i, j, v);
}

// One-to-one, only allowed pairs, and costing the reported total.
double check(const Problem& p, std::span<const int> col, double reported) {
  REQUIRE(col.size() == static_cast<std::size_t>(p.rows));
  std::vector<int> taken(static_cast<std::size_t>(p.cols), 0);
  const std::vector<double> c = dense(p);
  const int w = p.cols + p.rows;
  double total = 0.0;
  for (int i = 0; i < p.rows; ++i) {
    const int j = col[static_cast<std::size_t>(i)];
    if (j < 0) {
      total += p.none[static_cast<std::size_t>(i)];
      continue;
    }
    REQUIRE(j < p.cols);
    REQUIRE(taken[static_cast<std::size_t>(j)]++ == 0);
    REQUIRE(std::isfinite(c[static_cast<std::size_t>(i * w + j)]));
    total += c[static_cast<std::size_t>(i * w + j)];
  }
  CHECK(total == Approx(reported).margin(1e-9));
  return total;
}

}  // namespace

TEST_CASE("= dense and brute force on 6000 problems up to 8x8") {
  std::mt19937_64 rng(21);
  SparseAssignment sparse;
  LinearAssignment dense_solver;
  BruteForceAssignment brute;
  for (int k = 0; k < 6000; ++k) {
    const Problem p = random_problem(rng, 8, 8, k % 2 == 0);
    load(sparse, p);
    const std::span<const int> col = sparse.solve();
    const double got = check(p, col, sparse.total_cost());
    const std::vector<double> c = dense(p);
    const int w = p.cols + p.rows;
    const double want = p.rows == 0 ? 0.0 : dense_solver.solve(std::span<const double>(c), p.rows, w).total_cost;
    CHECK(got == Approx(want).margin(1e-9));
    if (p.rows <= 5 && p.cols <= 6) {
      const double bf = p.rows == 0 ? 0.0 : brute.solve(c, p.rows, w).total_cost;
      CHECK(got == Approx(bf).margin(1e-9));
    }
  }
}

TEST_CASE("equals the dense problem on large sparse problems") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SparseAssignment sparse;
  LinearAssignment dense_solver;
  for (int k = 0; k < 12; ++k) {
    Problem p;
    p.rows = 150 + 20 * k;
    p.cols = 300 - 10 * k;
    for (int i = 0; i < p.rows; ++i) p.none.push_back(5.0 * u(rng));
    // Points on a line: row i may take columns near its own position (banded, chained clusters).
    for (int i = 0; i < p.rows; ++i)
      for (int j = 0; j < p.cols; ++j) {
        const double d = std::abs(static_cast<double>(i) / p.rows - static_cast<double>(j) / p.cols);
        if (d < 0.004 * (1 + k % 4) || u(rng) < 0.001) p.pairs.emplace_back(i, j, 10.0 * d * p.rows + u(rng));
      }
    load(sparse, p);
    const std::span<const int> col = sparse.solve();  // before total_cost(): argument order is unspecified
    const double got = check(p, col, sparse.total_cost());
    const std::vector<double> c = dense(p);
    CHECK(got == Approx(dense_solver.solve(std::span<const double>(c), p.rows, p.cols + p.rows).total_cost).epsilon(1e-12));
    CHECK(sparse.clusters() >= 1);
  }
}

TEST_CASE("pair order does not matter, duplicates count cheaper") {
  std::mt19937_64 rng(8);
  SparseAssignment a, b;
  for (int k = 0; k < 500; ++k) {
    Problem p = random_problem(rng, 8, 8, true);  // integer costs: many ties
    load(a, p);
    const std::vector<int> first(a.solve().begin(), a.solve().end());
    Problem q = p;
    std::shuffle(q.pairs.begin(), q.pairs.end(), rng);
    if (!q.pairs.empty()) {
      auto [i, j, v] = q.pairs.front();
      q.pairs.emplace_back(i, j, v + 1.0);  // a dearer duplicate changes nothing
    }
    load(b, q);
    const std::span<const int> second = b.solve();
    REQUIRE(std::vector<int>(second.begin(), second.end()) == first);
    CHECK(b.total_cost() == a.total_cost());
  }
}

TEST_CASE("hand-worked: two rows compete for one column") {
  SparseAssignment s;
  s.clear(3, 2);
  s.set_none_cost(0, 5.0);
  s.set_none_cost(1, 5.0);
  s.set_none_cost(2, 1.0);
  s.add(0, 0, 1.0);  // row 0 alone would take column 0 (1 < 5) ...
  s.add(1, 0, 2.0);
  s.add(1, 1, 9.0);  // ... and so would row 1 (2 < 9 and < 5): together 1 + 5 (row 1 misses) = 6 < 2 + 5 = 7
  const std::span<const int> col = s.solve();
  CHECK(col[0] == 0);
  CHECK(col[1] == -1);
  CHECK(col[2] == -1);
  CHECK(s.total_cost() == 7.0);  // 1 + 5 + 1
  CHECK(s.clusters() == 1);
}

TEST_CASE("bad input is refused") {
  SparseAssignment s;
  CHECK_THROWS_AS(s.clear(-1, 2), std::invalid_argument);
  s.clear(2, 2);
  CHECK_THROWS_AS(s.add(2, 0, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0, 2, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0, 0, kInf), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0, 0, std::nan("")), std::invalid_argument);
  CHECK_THROWS_AS(s.set_none_cost(0, kInf), std::invalid_argument);
  s.clear(0, 0);
  CHECK(s.solve().empty());
}
