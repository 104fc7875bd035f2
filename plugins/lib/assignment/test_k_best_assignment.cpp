// Purpose: KBestAssignment (Murty) against an enumeration of every assignment, LinearAssignment, the tracking form and bad input.
#include "assignment/k_best_assignment.hpp"

#include "assignment/linear_assignment.hpp"
#include "one_to_one_check.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

using trackflow::assignment::KBestAssignment;
using trackflow::assignment::LinearAssignment;
using trackflow::assignment::RankedAssignment;
using trackflow::assignment::test::require_one_to_one;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double cost_at(const std::vector<double>& cost, int cols, int i, int j) {
  return cost[static_cast<std::size_t>(i) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(j)];
}

std::vector<int> copy_of(std::span<const int> s) { return {s.begin(), s.end()}; }

// One feasible assignment found by enumeration: its column of each row and its total.
struct Enumerated {
  std::vector<int> column_for_row;
  double total = 0.0;
};

// Every one-to-one assignment covering the smaller side through finite entries, by depth-first
// enumeration over the rows: a row takes a free column, or (only when rows > cols) none, while
// enough rows remain to cover every column. Independent of Murty's partition and of
// LinearAssignment; sorted by total (ties in enumeration order).
std::vector<Enumerated> enumerate_all(const std::vector<double>& cost, int rows, int cols) {
  std::vector<Enumerated> all;
  std::vector<int> column(static_cast<std::size_t>(rows), -1);
  std::vector<bool> used(static_cast<std::size_t>(cols), false);
  const int pairs_needed = std::min(rows, cols);
  auto visit = [&](auto&& self, int i, int pairs, double so_far) -> void {
    if (i == rows) {
      if (pairs == pairs_needed) all.push_back({column, so_far});
      return;
    }
    if (pairs + (rows - i) > pairs_needed) {  // this row may stay unassigned
      column[static_cast<std::size_t>(i)] = -1;
      self(self, i + 1, pairs, so_far);
    }
    if (pairs == pairs_needed) return;
    for (int j = 0; j < cols; ++j) {
      if (used[static_cast<std::size_t>(j)] || std::isinf(cost_at(cost, cols, i, j))) continue;
      used[static_cast<std::size_t>(j)] = true;
      column[static_cast<std::size_t>(i)] = j;
      self(self, i + 1, pairs + 1, so_far + cost_at(cost, cols, i, j));
      used[static_cast<std::size_t>(j)] = false;
    }
    column[static_cast<std::size_t>(i)] = -1;
  };
  visit(visit, 0, 0, 0.0);
  std::stable_sort(all.begin(), all.end(), [](const Enumerated& a, const Enumerated& b) { return a.total < b.total; });
  return all;
}

// Each answer is one-to-one, covers the smaller side through finite entries and costs what its
// entries sum to; the answers are sorted and pairwise distinct. Returns them as column vectors.
std::vector<std::vector<int>> check_answers(std::span<const RankedAssignment> got, const std::vector<double>& cost,
                                            int rows, int cols, bool exact) {
  std::vector<std::vector<int>> columns;
  std::set<std::vector<int>> distinct;
  for (std::size_t a = 0; a < got.size(); ++a) {
    const RankedAssignment& r = got[a];
    REQUIRE(r.column_for_row.size() == static_cast<std::size_t>(rows));
    REQUIRE(require_one_to_one(r.column_for_row, cols) == std::min(rows, cols));
    double sum = 0.0;
    for (int i = 0; i < rows; ++i) {
      const int j = r.column_for_row[static_cast<std::size_t>(i)];
      if (j < 0) continue;
      REQUIRE(std::isfinite(cost_at(cost, cols, i, j)));
      sum += cost_at(cost, cols, i, j);
    }
    if (exact)
      REQUIRE(sum == r.total_cost);
    else
      REQUIRE(std::abs(sum - r.total_cost) <= 1e-12 * std::max(1.0, std::abs(sum)));
    if (a > 0) REQUIRE(got[a - 1].total_cost <= r.total_cost);
    columns.push_back(copy_of(r.column_for_row));
    REQUIRE(distinct.insert(columns.back()).second);
  }
  return columns;
}

enum class CostKind { small_integers, signed_integers, real, real_ties };

std::vector<double> random_problem(std::mt19937_64& rng, int rows, int cols, CostKind kind, double forbid) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> cost(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  for (double& c : cost) {
    switch (kind) {
      case CostKind::small_integers: c = static_cast<double>(rng() % 4); break;  // many ties
      case CostKind::signed_integers: c = static_cast<double>(static_cast<int>(rng() % 21) - 6); break;
      case CostKind::real: c = 10.0 * unit(rng) - 2.0; break;
      // 0.1 * k is inexact: equal totals by value that sum to different doubles in different orders.
      case CostKind::real_ties: c = 0.1 * static_cast<double>(rng() % 6); break;
    }
    if (unit(rng) < forbid) c = kInf;
  }
  return cost;
}

}  // namespace

TEST_CASE("all k against enumeration on 2400 random problems up to 6x6", "[k_best]") {
  std::mt19937_64 rng(20261204);
  KBestAssignment kbest;
  const double forbids[] = {0.0, 0.2, 0.45};
  int problems = 0, infeasible = 0, with_ties = 0, square = 0, wide = 0, tall = 0, every_k = 0;
  long long answers_compared = 0;
  for (int n = 0; n < 2400; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 6);
    const int cols = 1 + static_cast<int>(rng() % 6);
    const auto kind = static_cast<CostKind>(n % 4);
    const double forbid = forbids[(n / 4) % 3];
    // Integer sums are exact in double.
    const bool exact = kind == CostKind::small_integers || kind == CostKind::signed_integers;
    const std::vector<double> cost = random_problem(rng, rows, cols, kind, forbid);
    INFO("problem " << n << ": " << rows << " x " << cols << ", kind " << static_cast<int>(kind) << ", forbid "
                    << forbid);
    ++problems;
    square += rows == cols;
    wide += rows < cols;
    tall += rows > cols;
    const std::vector<Enumerated> all = enumerate_all(cost, rows, cols);
    const int count = static_cast<int>(all.size());
    if (count == 0) ++infeasible;
    for (int a = 1; a < count; ++a) with_ties += all[static_cast<std::size_t>(a)].total == all[static_cast<std::size_t>(a - 1)].total;

    // Every assignment at once, and more asked than exist: exactly the enumerated ones.
    const auto everything = kbest.solve(cost, rows, cols, count + 3);
    REQUIRE(static_cast<int>(everything.size()) == count);
    const std::vector<std::vector<int>> full = check_answers(everything, cost, rows, cols, exact);
    std::set<std::vector<int>> expected_set, got_set(full.begin(), full.end());
    for (const Enumerated& e : all) expected_set.insert(e.column_for_row);
    REQUIRE(got_set == expected_set);
    for (int a = 0; a < count; ++a) {
      const double want = all[static_cast<std::size_t>(a)].total;
      const double have = everything[static_cast<std::size_t>(a)].total_cost;
      if (exact)
        REQUIRE(have == want);
      else
        REQUIRE(std::abs(have - want) <= 1e-9 * std::max(1.0, std::abs(want)));
    }
    answers_compared += count;

    // Each k on its own: the k best totals, and (integer costs) the first k answers of the full run.
    const bool all_k = count <= 60;
    every_k += all_k;
    for (int k = 1; k <= count; ++k) {
      if (!all_k && !(k <= 3 || k == count / 3 || k == count / 2 || k >= count - 1)) continue;
      const auto got = kbest.solve(cost, rows, cols, k);
      REQUIRE(static_cast<int>(got.size()) == k);
      const std::vector<std::vector<int>> cols_k = check_answers(got, cost, rows, cols, exact);
      for (int a = 0; a < k; ++a) {
        const double want = all[static_cast<std::size_t>(a)].total;
        if (exact) {
          REQUIRE(got[static_cast<std::size_t>(a)].total_cost == want);
          REQUIRE(cols_k[static_cast<std::size_t>(a)] == full[static_cast<std::size_t>(a)]);
        } else {
          REQUIRE(std::abs(got[static_cast<std::size_t>(a)].total_cost - want) <= 1e-9 * std::max(1.0, std::abs(want)));
        }
      }
      answers_compared += k;
    }
  }
  // The mix must contain what it is meant to test.
  CHECK(problems == 2400);
  CHECK(infeasible >= 60);
  CHECK(with_ties >= 10000);
  CHECK(square >= 300);
  CHECK(wide >= 800);
  CHECK(tall >= 800);
  CHECK(every_k >= 1500);
  WARN("enumeration: " << problems << " problems (" << square << " square, " << wide << " wide, " << tall
                       << " tall), " << infeasible << " infeasible, " << with_ties << " tied neighbours, "
                       << answers_compared << " answers compared, every k on " << every_k);
}

TEST_CASE("best 300 of 40 random problems up to 8x9 against enumeration", "[k_best]") {
  // Deeper partition trees than 6x6 gives (more fixed lines, longer forbidden lists).
  std::mt19937_64 rng(808);
  KBestAssignment kbest;
  int compared = 0;
  for (int n = 0; n < 40; ++n) {
    const int small = 7 + static_cast<int>(rng() % 2), large = small + static_cast<int>(rng() % 2);
    const bool tall = n % 2 == 1;
    const int rows = tall ? large : small, cols = tall ? small : large;
    const auto kind = static_cast<CostKind>(n % 4);
    const bool exact = kind == CostKind::small_integers || kind == CostKind::signed_integers;
    const std::vector<double> cost = random_problem(rng, rows, cols, kind, 0.15);
    INFO("problem " << n << ": " << rows << " x " << cols << ", kind " << static_cast<int>(kind));
    const std::vector<Enumerated> all = enumerate_all(cost, rows, cols);
    const auto got = kbest.solve(cost, rows, cols, 300);
    REQUIRE(got.size() == std::min<std::size_t>(300, all.size()));
    check_answers(got, cost, rows, cols, exact);
    for (std::size_t a = 0; a < got.size(); ++a) {
      const double want = all[a].total;
      if (exact)
        REQUIRE(got[a].total_cost == want);
      else
        REQUIRE(std::abs(got[a].total_cost - want) <= 1e-9 * std::max(1.0, std::abs(want)));
    }
    compared += got.size() == 300;
  }
  CHECK(compared >= 30);
}

TEST_CASE("k = 1 is the optimum of LinearAssignment", "[k_best]") {
  std::mt19937_64 rng(5);
  KBestAssignment kbest;
  LinearAssignment linear;
  int feasible = 0;
  for (int n = 0; n < 500; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 10), cols = 1 + static_cast<int>(rng() % 10);
    const auto kind = static_cast<CostKind>(n % 3);
    const std::vector<double> cost = random_problem(rng, rows, cols, kind, 0.3);
    const auto expected = linear.solve(cost, rows, cols);
    const auto got = kbest.solve(cost, rows, cols, 1);
    REQUIRE(got.size() == (expected.feasible ? 1U : 0U));
    if (!expected.feasible) continue;
    ++feasible;
    CHECK(got[0].total_cost == expected.total_cost);
    CHECK(copy_of(got[0].column_for_row) == copy_of(expected.column_for_row));
  }
  CHECK(feasible >= 200);
}

TEST_CASE("hand-worked 3x3: the six permutations in order", "[k_best]") {
  // Column orders 012, 021, 102, 120, 201, 210 cost 11, 12, 5, 10, 7, 11 (the LinearAssignment
  // test's matrix): ranked 5, 7, 10, 11, 11, 12.
  const std::vector<double> c = {4, 1, 3,  //
                                 2, 5, 6,  //
                                 3, 2, 2};
  KBestAssignment kbest;
  const auto got = kbest.solve(c, 3, 3, 10);
  REQUIRE(got.size() == 6);
  const double totals[] = {5, 7, 10, 11, 11, 12};
  for (std::size_t a = 0; a < 6; ++a) CHECK(got[a].total_cost == totals[a]);
  CHECK(copy_of(got[0].column_for_row) == std::vector<int>{1, 0, 2});
  CHECK(copy_of(got[1].column_for_row) == std::vector<int>{2, 0, 1});
  CHECK(copy_of(got[2].column_for_row) == std::vector<int>{1, 2, 0});
  CHECK(copy_of(got[5].column_for_row) == std::vector<int>{0, 2, 1});
  // k = 1: the root only, not partitioned (nothing more is wanted). k = 2: the root and its
  // three children (one per free row; the third, all rows but row 2 fixed, is infeasible).
  REQUIRE(kbest.solve(c, 3, 3, 1).size() == 1);
  CHECK(kbest.subproblems_solved() == 1);
  REQUIRE(kbest.solve(c, 3, 3, 2).size() == 2);
  CHECK(kbest.subproblems_solved() == 4);
}

TEST_CASE("counts: more than exist or infeasible or empty or k = 0", "[k_best]") {
  KBestAssignment kbest;
  SECTION("2x3 has 6 assignments, 3x2 too") {
    const std::vector<double> c = {1, 2, 3,  //
                                   4, 5, 6};
    CHECK(kbest.solve(c, 2, 3, 100).size() == 6);
    CHECK(kbest.solve(c, 3, 2, 100).size() == 6);
    CHECK(kbest.solve(c, 2, 3, 4).size() == 4);
  }
  SECTION("forbidden entries leave 1") {
    const std::vector<double> c = {1, kInf,  //
                                   kInf, 2};
    const auto got = kbest.solve(c, 2, 2, 5);
    REQUIRE(got.size() == 1);
    CHECK(got[0].total_cost == 3.0);
  }
  SECTION("infeasible: a row with no allowed column, or two rows on one column") {
    CHECK(kbest.solve(std::vector<double>{kInf, kInf, 1, 2}, 2, 2, 3).empty());
    CHECK(kbest.solve(std::vector<double>{1, kInf, 2, kInf}, 2, 2, 3).empty());
    CHECK(kbest.solve(std::vector<double>{1, kInf, 2, kInf, 3, kInf}, 3, 2, 3).empty());
  }
  SECTION("an empty side: the one empty assignment") {
    const auto a = kbest.solve(std::vector<double>{}, 0, 3, 4);
    REQUIRE(a.size() == 1);
    CHECK(a[0].total_cost == 0.0);
    CHECK(a[0].column_for_row.empty());
    const auto b = kbest.solve(std::vector<double>{}, 3, 0, 4);
    REQUIRE(b.size() == 1);
    CHECK(copy_of(b[0].column_for_row) == std::vector<int>{-1, -1, -1});
  }
  SECTION("k = 0") { CHECK(kbest.solve(std::vector<double>{1, 2, 3, 4}, 2, 2, 0).empty()); }
}

TEST_CASE("tracking form: n tracks x (m detections + n private misses)", "[k_best]") {
  // Track i either takes a gated detection j at cost d(i, j) or misses at its own cost miss(i),
  // the column m + i; every other miss column is forbidden to it. The joint hypotheses are
  // enumerated here directly (per track: miss or a free gated detection), not as assignments.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  KBestAssignment kbest;
  int problems = 0;
  long long hypotheses = 0;
  for (int p = 0; p < 300; ++p) {
    const int tracks = 1 + static_cast<int>(rng() % 5), detections = static_cast<int>(rng() % 6);
    const int cols = detections + tracks;
    const bool integer = p % 2 == 0;
    std::vector<double> cost(static_cast<std::size_t>(tracks * cols), kInf);
    std::vector<double> miss(static_cast<std::size_t>(tracks));
    for (int i = 0; i < tracks; ++i) {
      for (int j = 0; j < detections; ++j)
        if (unit(rng) < 0.6)
          cost[static_cast<std::size_t>(i * cols + j)] =
              integer ? static_cast<double>(rng() % 7) - 3.0 : -5.0 + 8.0 * unit(rng);  // gated: -log likelihood ratio
      miss[static_cast<std::size_t>(i)] = integer ? 1.0 : 0.5 + unit(rng);
      cost[static_cast<std::size_t>(i * cols + detections + i)] = miss[static_cast<std::size_t>(i)];
    }
    // The hypotheses: detection of each track, -1 for a miss.
    std::vector<std::pair<double, std::vector<int>>> expected;
    std::vector<int> choice(static_cast<std::size_t>(tracks), -1);
    std::vector<bool> used(static_cast<std::size_t>(detections), false);
    auto visit = [&](auto&& self, int i, double so_far) -> void {
      if (i == tracks) {
        expected.push_back({so_far, choice});
        return;
      }
      choice[static_cast<std::size_t>(i)] = -1;
      self(self, i + 1, so_far + miss[static_cast<std::size_t>(i)]);
      for (int j = 0; j < detections; ++j) {
        const double c = cost[static_cast<std::size_t>(i * cols + j)];
        if (used[static_cast<std::size_t>(j)] || std::isinf(c)) continue;
        used[static_cast<std::size_t>(j)] = true;
        choice[static_cast<std::size_t>(i)] = j;
        self(self, i + 1, so_far + c);
        used[static_cast<std::size_t>(j)] = false;
      }
      choice[static_cast<std::size_t>(i)] = -1;
    };
    visit(visit, 0, 0.0);
    std::stable_sort(expected.begin(), expected.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const int count = static_cast<int>(expected.size());
    INFO("problem " << p << ": " << tracks << " tracks, " << detections << " detections, " << count << " hypotheses");

    for (const int k : {1, 3, count, count + 2}) {
      const auto got = kbest.solve(cost, tracks, cols, k);
      REQUIRE(static_cast<int>(got.size()) == std::min(k, count));
      check_answers(got, cost, tracks, cols, integer);
      std::set<std::vector<int>> seen;
      for (std::size_t a = 0; a < got.size(); ++a) {
        std::vector<int> hypothesis(static_cast<std::size_t>(tracks));
        for (int i = 0; i < tracks; ++i) {
          const int j = got[a].column_for_row[static_cast<std::size_t>(i)];
          if (j >= detections) REQUIRE(j == detections + i);  // only its own miss column
          hypothesis[static_cast<std::size_t>(i)] = j < detections ? j : -1;
        }
        REQUIRE(seen.insert(hypothesis).second);
        const double want = expected[a].first;
        if (integer)
          REQUIRE(got[a].total_cost == want);
        else
          REQUIRE(std::abs(got[a].total_cost - want) <= 1e-9 * std::max(1.0, std::abs(want)));
      }
      if (k >= count) {
        std::set<std::vector<int>> all;
        for (const auto& e : expected) all.insert(e.second);
        REQUIRE(seen == all);
      }
    }
    ++problems;
    hypotheses += count;
  }
  CHECK(problems == 300);
  CHECK(hypotheses >= 3000);
  WARN("tracking form: " << problems << " problems, " << hypotheses << " joint hypotheses ranked");
}

TEST_CASE("deterministic: same output for any solver and storage order", "[k_best]") {
  std::mt19937_64 rng(99);
  KBestAssignment a, b;
  int compared = 0;
  for (int n = 0; n < 100; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 8), cols = 1 + static_cast<int>(rng() % 8);
    const std::vector<double> cost = random_problem(rng, rows, cols, CostKind::small_integers, 0.15);
    const int k = 1 + static_cast<int>(rng() % 40);
    std::vector<std::pair<double, std::vector<int>>> first;
    for (const RankedAssignment& r : a.solve(cost, rows, cols, k)) first.push_back({r.total_cost, copy_of(r.column_for_row)});
    auto same = [&](std::span<const RankedAssignment> got) {
      REQUIRE(got.size() == first.size());
      for (std::size_t q = 0; q < got.size(); ++q) {
        REQUIRE(got[q].total_cost == first[q].first);
        REQUIRE(copy_of(got[q].column_for_row) == first[q].second);
      }
    };
    same(a.solve(cost, rows, cols, k));
    KBestAssignment fresh;
    same(fresh.solve(cost, rows, cols, k));
    same(b.solve(cost, rows, cols, k));
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> row_major(
        cost.data(), rows, cols);
    const Eigen::MatrixXd col_major = row_major;
    same(b.solve(row_major, k));
    same(b.solve(col_major, k));
    compared += static_cast<int>(first.size()) > 1;
  }
  CHECK(compared >= 80);
}

TEST_CASE("storage is reused and not reallocated", "[k_best]") {
  std::mt19937_64 rng(3);
  KBestAssignment kbest(6, 8, 20);
  const std::vector<double> big = random_problem(rng, 6, 8, CostKind::real, 0.0);
  kbest.solve(big, 6, 8, 20);  // grows whatever reserve() could not foresee
  const auto first = kbest.solve(big, 6, 8, 20);
  REQUIRE(first.size() == 20);
  const RankedAssignment* answers = first.data();
  const int* columns = first[0].column_for_row.data();
  for (int n = 0; n < 100; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 6), cols = 1 + static_cast<int>(rng() % 8);
    kbest.solve(random_problem(rng, rows, cols, CostKind::real, 0.1), rows, cols, 1 + static_cast<int>(rng() % 20));
    const auto again = kbest.solve(big, 6, 8, 20);
    REQUIRE(again.data() == answers);
    REQUIRE(again[0].column_for_row.data() == columns);
  }
}

TEST_CASE("bad input is refused with a clear exception", "[k_best]") {
  KBestAssignment kbest;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(kbest.solve(std::vector<double>{1, nan, 2, 3}, 2, 2, 2), std::invalid_argument);
  CHECK_THROWS_WITH(kbest.solve(std::vector<double>{1, nan, 2, 3}, 2, 2, 2), Catch::Contains("is NaN"));
  CHECK_THROWS_WITH(kbest.solve(std::vector<double>{1, 2, -kInf, 3}, 2, 2, 2), Catch::Contains("-infinity"));
  CHECK_THROWS_WITH(kbest.solve(std::vector<double>{1, 2, 3, 4, 5, nan}, 3, 2, 2), Catch::Contains("cost(2, 1) is NaN"));
  CHECK_THROWS_WITH(kbest.solve(std::vector<double>{1, 2, 3, 4}, 2, 2, -1), Catch::Contains("negative"));
  CHECK_THROWS_WITH(kbest.solve(std::vector<double>{1, 2, 3}, 2, 2, 1), Catch::Contains("not 2 x 2"));
  CHECK_THROWS_WITH(kbest.reserve(2, 2, -3), Catch::Contains("negative"));
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3, 3);
  m(2, 1) = nan;
  CHECK_THROWS_WITH(kbest.solve(m, 2), Catch::Contains("cost(2, 1) is NaN"));
  // Still usable after refusing.
  const auto got = kbest.solve(std::vector<double>{2, 1}, 1, 2, 5);
  REQUIRE(got.size() == 2);
  CHECK(got[0].total_cost == 1.0);
  CHECK(got[1].total_cost == 2.0);
}

TEST_CASE("resume continues a search as a longer solve would", "[k_best]") {
  std::mt19937 gen(77);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int rows = 1 + trial % 5, cols = 1 + (trial / 5) % 6;
    std::vector<double> cost(static_cast<std::size_t>(rows * cols));
    for (double& c : cost) c = uniform(gen) < 0.2 ? std::numeric_limits<double>::infinity() : std::floor(uniform(gen) * 5);
    const int k1 = 1 + trial % 3, k2 = k1 + 1 + trial % 7;
    KBestAssignment once, twice;
    const auto full = once.solve(cost, rows, cols, k2);
    std::vector<std::pair<double, std::vector<int>>> expected;
    for (const auto& a : full) expected.push_back({a.total_cost, {a.column_for_row.begin(), a.column_for_row.end()}});
    const auto first = twice.solve(cost, rows, cols, k1);
    CHECK(first.size() == std::min<std::size_t>(expected.size(), static_cast<std::size_t>(k1)));
    const auto more = twice.resume(k2);
    REQUIRE(more.size() == expected.size());
    for (std::size_t q = 0; q < more.size(); ++q) {
      CHECK(more[q].total_cost == expected[q].first);
      CHECK(std::vector<int>(more[q].column_for_row.begin(), more[q].column_for_row.end()) == expected[q].second);
    }
    CHECK(twice.subproblems_solved() == once.subproblems_solved());  // nothing solved twice
  }
}
