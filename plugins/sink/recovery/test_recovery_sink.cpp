// Purpose: tests of sink.recovery fed synthetic estimates and truth: metrics against hand counts, non-finite estimates, run merging, parameter errors.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

// One run of 45 samples at 10 Hz: truth flies along x at 100 m/s; the estimate is off by
// `offset(k)` metres in y. Sample 2 is not yet initialised.
template <class Offset>
void feed(Component& sink, std::uint64_t run, Offset offset, bool with_nan = false) {
  Diagnostics d;
  sink.start_run({run, 1, &d});
  for (int k = 0; k < 45; ++k) {
    const double t = 0.1 * k;
    Truth truth;
    truth.time = t;
    truth.position = Vec3(100.0 * t, 0, 1000);
    truth.velocity = Vec3(100, 0, 0);
    Estimate e;
    e.time = t;
    e.initialised = k >= 3;
    e.enu = Vec6::Zero();
    e.enu_covariance = Mat6::Identity();
    if (e.initialised) e.enu.head<3>() = truth.position + Vec3(0, offset(k), 0);
    if (with_nan && k == 40) e.enu(1) = std::numeric_limits<double>::quiet_NaN();
    // Estimates may arrive before or after the truth of their step.
    if (k % 2) {
      sink.on_estimate(e, 0);
      sink.on_truth(truth, 1);
    } else {
      sink.on_truth(truth, 1);
      sink.on_estimate(e, 0);
    }
  }
  auto r = sink.end_run();
  sink.merge(*r);
}

double metric(const Summary& s, const char* name) {
  const Metric* m = s.find(name);
  INFO(name);
  REQUIRE(m);
  return m->value;
}

}  // namespace

// recovery metrics, peak error and RMSE outside bursts over two runs
TEST_CASE("recovery metrics over two runs") {
  // Bursts of 3 samples at 10, 30 (period 20). Run 0 recovers 4 samples after burst 1 and at
  // once after burst 2; run 1 needs 6 and 1.
  auto sink = test::make("sink.recovery", "{ shot_length: 3, shot_period: 20, shot_offset: 10, threshold: 2 m }");
  auto run0 = [](int k) -> double {
    if (k >= 10 && k < 13) return 40.0;
    if (k >= 13 && k < 17) return 10.0 - k / 10.0;  // 8.7, 8.6, 8.5, 8.4
    if (k >= 30 && k < 33) return -25.0;
    return 1.0;
  };
  auto run1 = [](int k) -> double {
    if (k >= 10 && k < 13) return 60.0;
    if (k >= 13 && k < 19) return 3.0;
    if (k >= 30 && k < 33) return 5.0;
    if (k == 33) return 2.5;
    return -0.5;
  };
  feed(*sink, 0, run0);
  feed(*sink, 1, run1, /*with_nan=*/true);
  Summary s;
  sink->finish(s, {"rec", "", 2});
  CHECK(metric(s, "bursts") == 4);
  CHECK(metric(s, "unrecovered_bursts") == 0);
  CHECK(metric(s, "mean_recovery_samples") == Approx((4 + 0 + 6 + 1) / 4.0));
  CHECK(metric(s, "max_recovery_samples") == 6);
  CHECK(metric(s, "mean_peak_error") == Approx((40 + 25 + 60 + 5) / 4.0));
  CHECK(metric(s, "non_finite_estimates") == 1);
  // RMSE over initialised samples (3..44) outside the burst samples 10-12 and 30-32, and not the NaN one.
  double sq = 0;
  int n = 0;
  for (int k = 3; k < 45; ++k) {
    if ((k >= 10 && k < 13) || (k >= 30 && k < 33)) continue;
    sq += run0(k) * run0(k);
    ++n;
    if (k == 40) continue;
    sq += run1(k) * run1(k);
    ++n;
  }
  CHECK(metric(s, "rmse_excluding_bursts") == Approx(std::sqrt(sq / n)));
}

// skip_initial leaves the transient out of the RMSE; hold requires consecutive samples
TEST_CASE("skip_initial and consecutive hold samples") {
  auto sink = test::make("sink.recovery",
                         "{ shot_length: 3, shot_period: 20, shot_offset: 10, threshold: 2 m, hold: 3, skip_initial: 1 s }");
  // Large error in the first second after initialisation (t 0.3 .. 1.2); after burst 1 a single
  // sample within, then within from 16 on.
  feed(*sink, 0, [](int k) -> double {
    if (k < 10) return 100.0;
    if (k < 13) return 50.0;
    if (k == 13) return 1.0;
    if (k < 16) return 9.0;
    return 1.0;
  });
  Summary s;
  sink->finish(s, {"rec", "", 1});
  // Burst 1: 13 (alone), 14, 15 out; 16, 17, 18 hold: 3. Burst 2 (no error in it): 0.
  CHECK(metric(s, "mean_recovery_samples") == 1.5);
  CHECK(metric(s, "max_recovery_samples") == 3);
  CHECK(metric(s, "rmse_excluding_bursts") > 1.0);  // 14, 15 at 9 m count
  double sq = 0;
  int n = 0;
  for (int k = 13; k < 45; ++k) {  // t >= 0.3 + 1.0 s, outside bursts
    if (k >= 30 && k < 33) continue;
    const double e = k == 14 || k == 15 ? 9.0 : 1.0;
    sq += e * e;
    ++n;
  }
  CHECK(metric(s, "rmse_excluding_bursts") == Approx(std::sqrt(sq / n)));
}

// sink.recovery refuses two filters and an exclusion longer than the period
TEST_CASE("refuses two filters and too long an exclusion") {
  auto sink = test::make("sink.recovery", "{ threshold: 10 m }");
  const std::vector<InputInfo> two = {{"a", "filter.ekf", mask(ItemKind::Estimate)},
                                      {"b", "filter.ekf", mask(ItemKind::Estimate)}};
  CHECK_THROWS_AS(sink->set_inputs(two), ConfigError);
  CHECK_THROWS_WITH(test::make("sink.recovery", "{ threshold: 10 m, shot_period: 20, shot_length: 5, exclude_after: 16 }"),
                    Catch::Contains("exclude_after"));
  CHECK_THROWS_WITH(test::make("sink.recovery", "{ shot_period: 20 }"), Catch::Contains("threshold"));
}
