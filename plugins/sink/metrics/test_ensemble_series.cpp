// Purpose: tests of sink.metrics' per-step ensemble series: values by hand, bands, fractions, annotations, and its mean equal to the summary.
#include <catch2/catch.hpp>

#include <limits>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

const InputInfo kFilter{"kf", "filter.kalman", mask(ItemKind::Estimate),
                        {"qs.grade_range", "qs.grade_azimuth", "qs.grade_elevation"}};
const InputInfo kTruth{"truth", "sim.trajectory", mask(ItemKind::Truth)};
const InputInfo kMeas{"cm", "convert.classical", mask(ItemKind::Measurement)};

// Two runs, steps at t = 0, 1, 2: at t = 0 only an uninitialised estimate; errors at t = 1, 2
// as given; measurements 3 m off in x at every step; run 1 carries quality grades.
Summary two_runs() {
  auto worker = test::make("sink.metrics", "{}", "score");
  auto aggregate = test::make("sink.metrics", "{}", "score");
  worker->set_inputs({kFilter, kTruth, kMeas});
  aggregate->set_inputs({kFilter, kTruth, kMeas});
  const double err[2][3] = {{0, 1, 2}, {0, 3, -2}};  // x error per run and step
  Diagnostics diag;
  for (int r = 0; r < 2; ++r) {
    worker->start_run({static_cast<std::uint64_t>(r), 1, &diag});
    for (int k = 0; k < 3; ++k) {
      Truth t;
      t.time = k;
      t.position = Vec3(100.0 * k, 0, 0);
      worker->on_truth(t, 1);
      Measurement m;
      m.time = k;
      m.frame = Frame::Cartesian;
      m.value = MeasVec::Zero(3);
      m.value(0) = t.position.x() + 3.0;
      m.covariance = MeasCov::Identity(3, 3);
      worker->on_measurement(m, 2);
      Estimate e;
      e.time = k;
      e.initialised = k > 0;
      e.updated = k == 1 || r == 0;
      e.enu = Vec6::Zero();
      e.enu(0) = t.position.x() + err[r][k];
      e.enu_covariance = Mat6::Identity();
      if (e.updated && e.initialised) {
        e.innovation = MeasVec::Zero(3);
        e.innovation_covariance = MeasCov::Identity(3, 3);
        e.nis = 3.0 * (r + 1);
      }
      e.annotation_count = 3;
      for (double& a : e.annotations) a = std::numeric_limits<double>::quiet_NaN();
      if (r == 1) e.annotations[0] = k;  // range grade 1 at t = 1, 2 at t = 2
      worker->on_estimate(e, 0);
    }
    auto res = worker->end_run();
    REQUIRE(res);
    aggregate->merge(*res);
  }
  Summary s;
  aggregate->finish(s, {"score", "", 2});
  return s;
}

double cell(const Series& s, size_t row, const std::string& col) {
  const int c = s.column(col);
  INFO("column " << col);
  REQUIRE(c >= 0);
  return s.at(row, static_cast<size_t>(c));
}

}  // namespace

TEST_CASE("ensemble series holds hand-computed per-step values") {
  const Summary s = two_runs();
  REQUIRE(s.series.size() == 1);
  const Series& e = s.series[0];
  CHECK(e.name == "ensemble");
  REQUIRE(e.rows() == 3);
  CHECK(e.columns[static_cast<size_t>(e.column("time"))].unit == "s");
  CHECK(e.columns[static_cast<size_t>(e.column("position_rmse"))].unit == "m");
  CHECK(e.columns[static_cast<size_t>(e.column("velocity_rmse"))].unit == "m/s");
  // Step t = 0: no initialised estimate, so no error; its measurements come before the scored
  // window (first initialised estimate + skip_initial), as in the summary.
  CHECK(cell(e, 0, "time") == 0.0);
  CHECK(std::isnan(cell(e, 0, "position_rmse")));
  CHECK(cell(e, 0, "initialised_fraction") == 0.0);
  CHECK(std::isnan(cell(e, 0, "measurement_rmse")));
  CHECK(cell(e, 1, "measurement_rmse") == Approx(3.0));
  // Step t = 1: x errors 1 and 3.
  CHECK(cell(e, 1, "position_rmse") == Approx(std::sqrt((1.0 + 9.0) / 2)));
  CHECK(cell(e, 1, "mean_error_x") == Approx(2.0));
  CHECK(cell(e, 1, "mean_error_y") == 0.0);
  CHECK(cell(e, 1, "anees") == Approx((1.0 + 9.0) / (6 * 2)));
  CHECK(cell(e, 1, "anis") == Approx((3.0 + 6.0) / (3 + 3)));
  CHECK(cell(e, 1, "initialised_fraction") == 1.0);
  CHECK(cell(e, 1, "updated_fraction") == 1.0);
  // Step t = 2: x errors 2 and -2, run 1 not updated.
  CHECK(cell(e, 2, "position_rmse") == Approx(2.0));
  CHECK(cell(e, 2, "mean_error_x") == Approx(0.0).margin(1e-12));
  CHECK(cell(e, 2, "updated_fraction") == 0.5);
  CHECK(cell(e, 2, "anis") == Approx(1.0));  // only run 0's NIS of 3 over 3 dimensions
  // Annotations: only run 1 carries a range grade; the other channels never occur.
  CHECK(cell(e, 1, "qs.grade_range_mean") == 1.0);
  CHECK(cell(e, 2, "qs.grade_range_mean") == 2.0);
  CHECK(e.column("qs.grade_azimuth_mean") < 0);
}

TEST_CASE("each step's band is the chi-square band of its runs") {
  const Summary s = two_runs();
  const Series& e = s.series[0];
  // 6 dof x 2 runs = 12: chi2 quantiles 4.404 and 23.337 at 95 %.
  CHECK(cell(e, 1, "anees_band_lo") == Approx(4.4038 / 12).epsilon(1e-3));
  CHECK(cell(e, 1, "anees_band_hi") == Approx(23.3367 / 12).epsilon(1e-3));
  // ANIS at t = 2: one run of 3 dof: 0.2158 and 9.3484.
  CHECK(cell(e, 2, "anis_band_lo") == Approx(0.21580 / 3).epsilon(1e-3));
  CHECK(cell(e, 2, "anis_band_hi") == Approx(9.3484 / 3).epsilon(1e-3));
}

TEST_CASE("the mean of the ANEES series is the summary's anees") {
  const Summary s = two_runs();
  const Series& e = s.series[0];
  double sum = 0.0;
  int n = 0;
  for (size_t r = 0; r < e.rows(); ++r)
    if (std::isfinite(cell(e, r, "anees"))) {
      sum += cell(e, r, "anees");
      ++n;
    }
  REQUIRE(n == 2);
  const Metric* a = s.find("anees");
  REQUIRE(a);
  CHECK(sum / n == Approx(a->value).epsilon(1e-12));
  // The uninitialised estimates do not count as scored estimates.
  CHECK(s.find("estimates")->value == 4);
}

// Runs that reach time steps no earlier run had -- between known steps, after them, and out of
// time order within a run -- still give one row per step in time order, each with its own sums.
TEST_CASE("steps new in later runs keep time order and sums") {
  auto worker = test::make("sink.metrics", "{}", "score");
  auto aggregate = test::make("sink.metrics", "{}", "score");
  worker->set_inputs({kFilter, kTruth});
  aggregate->set_inputs({kFilter, kTruth});
  // Estimate times and x errors per run (run 1 out of order: 3 before 1).
  const std::vector<std::vector<std::pair<double, double>>> runs = {
      {{0.0, 1.0}, {2.0, 1.0}, {4.0, 1.0}},
      {{3.0, 2.0}, {1.0, 3.0}, {4.0, 2.0}},
      {{0.0, 4.0}, {2.5, 5.0}, {5.0, 6.0}},
  };
  Diagnostics diag;
  for (size_t r = 0; r < runs.size(); ++r) {
    worker->start_run({r, 1, &diag});
    for (int k = 0; k <= 10; ++k) {
      Truth t;
      t.time = 0.5 * k;
      t.position = Vec3(10.0 * k, 0, 0);
      worker->on_truth(t, 1);
    }
    for (const auto& [time, error] : runs[r]) {
      Estimate e;
      e.time = time;
      e.initialised = true;
      e.enu = Vec6::Zero();
      e.enu(0) = 20.0 * time + error;  // truth x = 20 m/s * t
      e.enu_covariance = Mat6::Identity();
      worker->on_estimate(e, 0);
    }
    auto res = worker->end_run();
    REQUIRE(res);
    aggregate->merge(*res);
  }
  Summary s;
  aggregate->finish(s, {"score", "", runs.size()});
  REQUIRE(s.series.size() == 1);
  const Series& e = s.series[0];
  const double times[] = {0.0, 1.0, 2.0, 2.5, 3.0, 4.0, 5.0};
  const double scored[] = {2, 1, 1, 1, 1, 2, 1};
  const double rmse[] = {std::sqrt((1.0 + 16.0) / 2), 3.0, 1.0, 5.0, 2.0, std::sqrt((1.0 + 4.0) / 2), 6.0};
  REQUIRE(e.rows() == 7);
  for (size_t row = 0; row < 7; ++row) {
    INFO("row " << row);
    CHECK(cell(e, row, "time") == times[row]);
    CHECK(cell(e, row, "runs_scored") == scored[row]);
    CHECK(cell(e, row, "position_rmse") == Approx(rmse[row]));
  }
  CHECK(s.find("steps")->value == 7);
  CHECK(s.find("estimates")->value == 9);
}
