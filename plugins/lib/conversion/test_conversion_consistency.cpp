// Purpose: acceptance check of issue 3: Monte Carlo bias and NEES of all four convert.* plugins at the two standard geometries.
#include "consistency_study.hpp"

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <cstdio>
#include <map>

using namespace trackflow;
using namespace trackflow::conversion;

namespace {
constexpr std::uint64_t kDraws = 100000;
constexpr std::uint64_t kSeed = 20240603;  // the seed convert-consistency uses for docs/converters.md
// χ²(3) 0.999 quantile: an unbiased converter's Hotelling T² exceeds it once in a thousand seeds.
constexpr double kChi2_3_999 = 16.266;

std::map<std::string, StudyRow> study(const StudyGeometry& g) {
  const ComponentFactory make = [](const std::string& type) { return test::make(type); };
  std::map<std::string, StudyRow> rows;
  const auto list = run_study(make, study_converters(), g, kDraws, kSeed);
  std::printf("%s\n", markdown_table(list).c_str());
  for (const auto& r : list) rows[r.converter] = r;
  return rows;
}
}  // namespace

// geometry A (r σ²/σ_r ≈ 12): classical fails, modified unbiased is consistent, unbiased is unbiased
TEST_CASE("geometry A (large bias): classical fails") {
  const StudyGeometry g = standard_geometries().at(0);
  REQUIRE(g.nonlinearity() > 10.0);
  auto rows = study(g);
  for (const auto& [name, r] : rows) {
    CHECK(r.draws == kDraws);
    CHECK(r.not_positive_definite == 0);
  }

  // Classical: E[p(m)|t] = D p(t) falls short by about r σ² ≈ 120 m along the line of sight,
  // hundreds of standard errors; its J R J' has only σ_r² along the line of sight.
  const StudyRow& classical = rows.at("convert.classical");
  CHECK(classical.bias_mahalanobis > 100.0 * kChi2_3_999);
  CHECK(classical.nees_per_dim > 5.0);

  // Mo's conversion is unbiased given the truth: the fixed-truth mean error is noise.
  const StudyRow& unbiased = rows.at("convert.unbiased");
  for (int i = 0; i < 3; ++i) CHECK(std::abs(unbiased.bias_in_se(i)) < 3.0);
  CHECK(unbiased.bias_mahalanobis < kChi2_3_999);

  // The modified conversion is the posterior mean and covariance: consistent by construction.
  const StudyRow& modified = rows.at("convert.unbiased_modified");
  CHECK(modified.nees_per_dim >= 0.95);
  CHECK(modified.nees_per_dim <= 1.10);

  // Debiased: the residual bias given the truth is (D + D² - D³ - I) p(t) ≈ -2 (1 - λa λe)² p(t)
  // ≈ 0.3 m, below a standard error (≈ 0.6 m along the line of sight), so the bias test must pass.
  // Its R is thin along the *measured* line of sight, where the truth lies inward of p(m) while
  // the correction pushes outward: optimistic (issue 3 expects about 1.2), yet far from the classical.
  const StudyRow& debiased = rows.at("convert.debiased");
  CHECK(debiased.bias_mahalanobis < kChi2_3_999);
  CHECK(debiased.nees_per_dim > 1.0);
  CHECK(debiased.nees_per_dim < 2.0);
}

// geometry B (r σ²/σ_r = 0.001): every converter is consistent
TEST_CASE("geometry B (small bias): all are consistent") {
  const StudyGeometry g = standard_geometries().at(1);
  REQUIRE(g.nonlinearity() < 0.01);
  auto rows = study(g);
  for (const auto& [name, r] : rows) {
    INFO(name);
    CHECK(r.nees_per_dim >= 0.95);
    CHECK(r.nees_per_dim <= 1.05);
    CHECK(r.not_positive_definite == 0);
  }
  const StudyRow& unbiased = rows.at("convert.unbiased");
  for (int i = 0; i < 3; ++i) CHECK(std::abs(unbiased.bias_in_se(i)) < 3.0);
  CHECK(unbiased.bias_mahalanobis < kChi2_3_999);
}
