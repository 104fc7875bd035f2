// Purpose: LinearAssignment against brute-force enumeration, SciPy's answers, hand-worked cases and bad input.
#include "assignment/linear_assignment.hpp"

#include "brute_force_assignment.hpp"
#include "one_to_one_check.hpp"
#include "scipy_case_matrix.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using trackflow::assignment::AssignmentResult;
using trackflow::assignment::LinearAssignment;
using trackflow::assignment::test::BruteForceAssignment;
using trackflow::assignment::test::require_one_to_one;
using trackflow::assignment::test::scipy_case_matrix;
using trackflow::assignment::test::ScipyCaseRecipe;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double cost_at(const std::vector<double>& cost, int cols, int i, int j) {
  return cost[static_cast<std::size_t>(i) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(j)];
}

// A returned assignment must be one-to-one, cover the smaller side and use finite entries only.
// Returns what it costs, for the caller to compare with the reported total.
double check_assignment(const AssignmentResult& r, const std::vector<double>& cost, int rows, int cols) {
  REQUIRE(r.column_for_row.size() == static_cast<std::size_t>(rows));
  REQUIRE(require_one_to_one(r.column_for_row, cols) == std::min(rows, cols));
  double sum = 0.0;
  for (int i = 0; i < rows; ++i) {
    const int j = r.column_for_row[static_cast<std::size_t>(i)];
    if (j < 0) continue;
    REQUIRE(std::isfinite(cost_at(cost, cols, i, j)));
    sum += cost_at(cost, cols, i, j);
  }
  return sum;
}

std::vector<int> copy_of(std::span<const int> s) { return {s.begin(), s.end()}; }

enum class CostKind { real, small_integers, signed_integers, real_ties };

// One random problem of the brute-force comparison; `kind` and `forbid` vary with its index so
// that every combination is well represented.
std::vector<double> random_problem(std::mt19937_64& rng, int rows, int cols, CostKind kind, double forbid) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> cost(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  for (double& c : cost) {
    switch (kind) {
      case CostKind::real: c = 100.0 * unit(rng); break;
      case CostKind::small_integers: c = static_cast<double>(rng() % 5); break;
      case CostKind::signed_integers: c = static_cast<double>(static_cast<int>(rng() % 26) - 5); break;
      case CostKind::real_ties: c = 0.1 * static_cast<double>(rng() % 7); break;  // 0.1 * k is inexact: ties by value
    }
    if (unit(rng) < forbid) c = kInf;
  }
  return cost;
}

}  // namespace

TEST_CASE("equals brute force on 12000 random problems up to 9x9", "[assignment]") {
  std::mt19937_64 rng(20260217);
  LinearAssignment solver(9, 9);
  LinearAssignment second_solver;  // unreserved: the same answer with other storage
  BruteForceAssignment brute;
  const double forbids[] = {0.0, 0.15, 0.35, 0.6};
  int compared = 0, infeasible = 0, integer_problems = 0, with_forbidden = 0;
  for (int n = 0; n < 12000; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 9);
    const int cols = 1 + static_cast<int>(rng() % 9);
    const auto kind = static_cast<CostKind>(n % 4);
    const double forbid = forbids[(n / 4) % 4];
    const std::vector<double> cost = random_problem(rng, rows, cols, kind, forbid);
    INFO("problem " << n << ": " << rows << " x " << cols << ", kind " << static_cast<int>(kind) << ", forbid "
                    << forbid);

    const auto expected = brute.solve(cost, rows, cols);
    const AssignmentResult got = solver.solve(cost, rows, cols);
    REQUIRE(got.feasible == expected.feasible);
    ++compared;
    for (double c : cost) with_forbidden += std::isinf(c) ? 1 : 0;
    if (!got.feasible) {
      ++infeasible;
      CHECK(got.total_cost == kInf);
      for (int j : got.column_for_row) CHECK(j == -1);
      continue;
    }
    const double recomputed = check_assignment(got, cost, rows, cols);
    const bool integer = kind == CostKind::small_integers || kind == CostKind::signed_integers;
    if (integer) {
      // Sums of small integers are exact in double: any difference is a wrong answer.
      ++integer_problems;
      REQUIRE(got.total_cost == expected.total_cost);
      REQUIRE(recomputed == got.total_cost);
    } else {
      const double scale = std::max(1.0, std::abs(expected.total_cost));
      REQUIRE(std::abs(got.total_cost - expected.total_cost) <= 1e-9 * scale);
      REQUIRE(std::abs(recomputed - got.total_cost) <= 1e-12 * scale);
    }
    // Same input, same output: again with this solver and with one whose storage differs.
    const std::vector<int> first = copy_of(got.column_for_row);
    REQUIRE(copy_of(solver.solve(cost, rows, cols).column_for_row) == first);
    REQUIRE(copy_of(second_solver.solve(cost, rows, cols).column_for_row) == first);
  }
  // The mix must really contain what it is meant to test.
  CHECK(compared == 12000);
  CHECK(infeasible >= 300);
  CHECK(compared - infeasible >= 9000);
  CHECK(integer_problems >= 4000);
  CHECK(with_forbidden >= 50000);
  WARN("brute force: " << compared << " problems compared, " << infeasible << " infeasible in both");
}

TEST_CASE("equals SciPy on the committed large problems", "[assignment]") {
  const std::string path = std::string(TRACKFLOW_ASSIGNMENT_DATA_DIR) + "/scipy_cases.txt";
  std::ifstream in(path);
  REQUIRE(in.good());
  LinearAssignment solver;
  int cases = 0, infeasible = 0, same_assignment = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name, total_text;
    ScipyCaseRecipe recipe;
    int feasible = 0;
    fields >> name >> recipe.rows >> recipe.cols >> recipe.seed >> recipe.int_range >> recipe.forbid_per_mille >>
        recipe.hall >> feasible >> total_text;
    REQUIRE(fields);
    INFO("case " << name);
    const std::vector<double> cost = scipy_case_matrix(recipe);
    const AssignmentResult got = solver.solve(cost, recipe.rows, recipe.cols);
    ++cases;
    REQUIRE(got.feasible == (feasible == 1));
    if (!got.feasible) {
      ++infeasible;
      continue;
    }
    std::vector<int> scipy_columns(static_cast<std::size_t>(recipe.rows));
    for (int& j : scipy_columns) fields >> j;
    REQUIRE(fields);
    const double scipy_total = std::strtod(total_text.c_str(), nullptr);  // hexadecimal: exact

    // SciPy's own assignment, priced on the rebuilt matrix, must cost what SciPy reported: this
    // is what shows the matrix here is the matrix SciPy solved.
    double scipy_recomputed = 0.0;
    for (int i = 0; i < recipe.rows; ++i)
      if (scipy_columns[static_cast<std::size_t>(i)] >= 0)
        scipy_recomputed += cost_at(cost, recipe.cols, i, scipy_columns[static_cast<std::size_t>(i)]);
    const double scale = std::max(1.0, std::abs(scipy_total));
    REQUIRE(std::abs(scipy_recomputed - scipy_total) <= 1e-12 * scale);

    const double recomputed = check_assignment(got, cost, recipe.rows, recipe.cols);
    if (recipe.int_range > 0) {
      REQUIRE(got.total_cost == scipy_total);
      REQUIRE(recomputed == got.total_cost);
    } else {
      REQUIRE(std::abs(got.total_cost - scipy_total) <= 1e-9 * scale);
      REQUIRE(std::abs(recomputed - got.total_cost) <= 1e-9 * scale);
    }
    same_assignment += copy_of(got.column_for_row) == scipy_columns ? 1 : 0;
  }
  CHECK(cases == 14);
  CHECK(infeasible == 2);
  WARN("SciPy: " << cases << " problems compared, " << infeasible << " infeasible in both, " << same_assignment
                 << " with the very same assignment");
}

TEST_CASE("hand-worked problems", "[assignment]") {
  LinearAssignment solver;
  SECTION("3x3: all six permutations priced") {
    // Column orders 012, 021, 102, 120, 201, 210 cost 4+5+2 = 11, 4+6+2 = 12, 1+2+2 = 5,
    // 1+6+3 = 10, 3+2+2 = 7, 3+5+3 = 11: rows take columns 1, 0, 2, the only optimum.
    const std::vector<double> c = {4, 1, 3,  //
                                   2, 5, 6,  //
                                   3, 2, 2};
    const auto r = solver.solve(c, 3, 3);
    REQUIRE(r.feasible);
    CHECK(r.total_cost == 5.0);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{1, 0, 2});
  }
  SECTION("2x3: the greedy choice of row 0 is wrong") {
    // Row 0 alone would take column 0 (cost 1), leaving row 1 column 1 or 2 (10 or 11): 11.
    // Optimal: row 0 -> 1 (2), row 1 -> 0 (1): 3.
    const std::vector<double> c = {1, 2, 5,  //
                                   1, 10, 11};
    const auto r = solver.solve(c, 2, 3);
    REQUIRE(r.feasible);
    CHECK(r.total_cost == 3.0);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{1, 0});
  }
  SECTION("3x2 (more rows than columns): one row left out") {
    // Columns take rows 2 (1) and 0 (2) -- 3; row 1 is left unassigned.
    const std::vector<double> c = {7, 2,  //
                                   8, 9,  //
                                   1, 6};
    const auto r = solver.solve(c, 3, 2);
    REQUIRE(r.feasible);
    CHECK(r.total_cost == 3.0);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{1, -1, 0});
  }
  SECTION("forbidden entries steer the answer") {
    // Without the infinity row 0 would take column 0 (cost 0); with it: 0 -> 1 (5), 1 -> 0 (1).
    const std::vector<double> c = {kInf, 5,  //
                                   1, 0};
    const auto r = solver.solve(c, 2, 2);
    REQUIRE(r.feasible);
    CHECK(r.total_cost == 6.0);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{1, 0});
  }
  SECTION("infeasible: two rows share their only allowed column") {
    const std::vector<double> c = {1, kInf, kInf,  //
                                   2, kInf, kInf};
    const auto r = solver.solve(c, 2, 3);
    CHECK_FALSE(r.feasible);
    CHECK(r.total_cost == kInf);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{-1, -1});
  }
  SECTION("infeasible: everything forbidden, 1x1 and 3x4") {
    CHECK_FALSE(solver.solve(std::vector<double>{kInf}, 1, 1).feasible);
    CHECK_FALSE(solver.solve(std::vector<double>(12, kInf), 3, 4).feasible);
  }
  SECTION("empty problems are feasible at zero cost") {
    const auto none = solver.solve(std::span<const double>{}, 0, 5);
    CHECK(none.feasible);
    CHECK(none.total_cost == 0.0);
    CHECK(none.column_for_row.empty());
    const auto no_columns = solver.solve(std::span<const double>{}, 4, 0);
    CHECK(no_columns.feasible);
    CHECK(copy_of(no_columns.column_for_row) == std::vector<int>{-1, -1, -1, -1});
  }
  SECTION("negative and large costs") {
    const std::vector<double> c = {-1e6, 3, 0,  //
                                   -1e6, -1e6, 2};
    const auto r = solver.solve(c, 2, 3);
    REQUIRE(r.feasible);
    CHECK(r.total_cost == -2e6);
    CHECK(copy_of(r.column_for_row) == std::vector<int>{0, 1});
  }
}

TEST_CASE("Eigen matrices of either storage order agree", "[assignment]") {
  std::mt19937_64 rng(7);
  LinearAssignment solver;
  for (int n = 0; n < 50; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 12), cols = 1 + static_cast<int>(rng() % 12);
    const std::vector<double> cost = random_problem(rng, rows, cols, CostKind::real, 0.2);
    const auto expected = solver.solve(cost, rows, cols);
    const std::vector<int> expected_columns = copy_of(expected.column_for_row);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> row_major(
        cost.data(), rows, cols);
    const Eigen::MatrixXd col_major = row_major;
    const auto a = solver.solve(row_major);
    CHECK(a.feasible == expected.feasible);
    CHECK(copy_of(a.column_for_row) == expected_columns);
    const auto b = solver.solve(col_major);
    CHECK(b.feasible == expected.feasible);
    CHECK(copy_of(b.column_for_row) == expected_columns);
    if (expected.feasible) CHECK(b.total_cost == expected.total_cost);
  }
}

TEST_CASE("reserved storage is reused, not reallocated", "[assignment]") {
  std::mt19937_64 rng(11);
  LinearAssignment solver;
  solver.reserve(9, 9);
  const int* storage = nullptr;
  for (int n = 0; n < 200; ++n) {
    const int rows = 1 + static_cast<int>(rng() % 9), cols = 1 + static_cast<int>(rng() % 9);
    const auto r = solver.solve(random_problem(rng, rows, cols, CostKind::real, 0.1), rows, cols);
    if (!storage) storage = r.column_for_row.data();
    REQUIRE(r.column_for_row.data() == storage);
  }
}

TEST_CASE("bad input is refused with a clear exception", "[assignment]") {
  LinearAssignment solver;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(solver.solve(std::vector<double>{1, nan, 2, 3}, 2, 2), Catch::Contains("is NaN"));
  CHECK_THROWS_WITH(solver.solve(std::vector<double>{1, 2, -kInf, 3}, 2, 2), Catch::Contains("-infinity"));
  CHECK_THROWS_WITH(solver.solve(std::vector<double>{1, 2, 3, -1e301}, 2, 2), Catch::Contains("cost(1, 1) is -"));
  CHECK(solver.solve(std::vector<double>{1e300, -1e300, -1e300, 1e300}, 2, 2).total_cost == -2e300);
  CHECK_THROWS_WITH(solver.solve(std::vector<double>{1, 2}, -1, 2), Catch::Contains("negative size"));
  CHECK_THROWS_WITH(solver.reserve(3, -2), Catch::Contains("negative size"));
  CHECK_THROWS_WITH(solver.solve(std::vector<double>{1, 2, 3}, 2, 2), Catch::Contains("not 2 x 2"));
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3, 3);
  m(2, 1) = nan;
  CHECK_THROWS_WITH(solver.solve(m), Catch::Contains("cost(2, 1) is NaN"));
  // The solver stays usable after refusing.
  CHECK(solver.solve(std::vector<double>{2, 1}, 1, 2).total_cost == 1.0);
}
