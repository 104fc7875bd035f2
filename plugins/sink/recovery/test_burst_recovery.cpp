// Purpose: tests of the burst recovery evaluation on hand-made error series: recovery counts, hold, censoring, peak error, RMSE outside bursts.
#include "burst_recovery.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace trackflow::recovery;

namespace {

std::vector<Sample> series(const std::vector<double>& errors) {
  std::vector<Sample> s;
  for (double e : errors) s.push_back({e, std::isfinite(e)});
  return s;
}

Settings settings(long long hold, long long exclude_after = 0) {
  Settings s;
  s.bursts = {2, 10, 10};  // bursts at samples 10-11, 20-21, 30-31
  s.threshold = 1.0;
  s.hold = hold;
  s.exclude_after = exclude_after;
  return s;
}

// 35 samples: clean 0.5 everywhere except around the bursts.
std::vector<double> errors() {
  std::vector<double> e(35, 0.5);
  e[10] = 100;
  e[11] = 80;
  e[12] = 50;   // burst 1 tail: 50, 5, 0.8 (a dip), 2, then within from 16 on
  e[13] = 5;
  e[14] = 0.8;
  e[15] = 2;
  e[20] = 30;   // burst 2: within right after
  e[21] = 30;
  e[30] = 9;    // burst 3: never back before the run ends
  e[31] = 9;
  e[32] = 7;
  e[33] = 7;
  e[34] = 7;
  return e;
}

}  // namespace

// recovery samples with hold 1 and hold 2, censoring at the end of the run, peak error
TEST_CASE("recovery with hold 1 and 2 and censoring") {
  const auto s = series(errors());
  const RunStats one = evaluate(s, settings(1));
  REQUIRE(one.bursts.size() == 3);
  CHECK(one.bursts[0].recovered);
  CHECK(one.bursts[0].samples == 2);  // 12, 13 above; 14 (0.8) is within
  CHECK(one.bursts[0].peak_error == 100);
  CHECK(one.bursts[1].recovered);
  CHECK(one.bursts[1].samples == 0);
  CHECK(one.bursts[1].peak_error == 30);
  CHECK_FALSE(one.bursts[2].recovered);
  CHECK(one.bursts[2].samples == 3);  // 32, 33, 34: censored at the end
  CHECK(one.bursts[2].peak_error == 9);

  const RunStats two = evaluate(s, settings(2));
  CHECK(two.bursts[0].samples == 4);  // the dip at 14 does not hold; 16, 17 do
  CHECK(two.bursts[0].recovered);
  CHECK(two.bursts[1].samples == 0);
}

// a burst is judged only up to the next burst, and not at all when no sample follows it
TEST_CASE("a burst is judged only up to the next burst") {
  std::vector<double> e(31, 0.5);
  for (int k = 10; k < 20; ++k) e[k] = 5.0;  // never back before burst 2 at 20
  e[30] = 5.0;                                // burst 3 starts at 30, nothing after 31
  const RunStats r = evaluate(series(e), settings(1));
  REQUIRE(r.bursts.size() == 2);
  CHECK_FALSE(r.bursts[0].recovered);
  CHECK(r.bursts[0].samples == 8);  // 12..19
  CHECK(r.bursts[1].recovered);
}

// the RMSE leaves out burst samples and exclude_after tails, and unscored samples
TEST_CASE("RMSE leaves out bursts and exclude_after tails") {
  auto s = series(errors());
  s[3].scored = false;  // e.g. the initial transient
  double sq = 0, n = 0, sq_tail = 0, n_tail = 0;
  for (int k = 0; k < 35; ++k) {
    if (k == 3) continue;
    const bool burst = k >= 10 && (k - 10) % 10 < 2;
    const bool tail = k >= 10 && (k - 10) % 10 == 2;
    if (!burst) {
      sq += s[k].error * s[k].error;
      ++n;
    }
    if (!burst && !tail) {
      sq_tail += s[k].error * s[k].error;
      ++n_tail;
    }
  }
  const RunStats r0 = evaluate(s, settings(1, 0));
  CHECK(r0.count == n);
  CHECK(r0.sq_error == Approx(sq));
  const RunStats r1 = evaluate(s, settings(1, 1));
  CHECK(r1.count == n_tail);
  CHECK(r1.sq_error == Approx(sq_tail));
}

// samples without an error (not initialised, non-finite) never count as recovered
TEST_CASE("samples without an error never count as recovered") {
  std::vector<double> e(25, 0.5);
  e[12] = std::numeric_limits<double>::infinity();
  const RunStats r = evaluate(series(e), settings(1));
  CHECK(r.bursts[0].samples == 1);
  CHECK(std::isinf(r.bursts[0].peak_error));
}
