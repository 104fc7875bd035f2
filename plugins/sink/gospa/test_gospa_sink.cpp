// Purpose: tests of sink.gospa fed hand-made truths and track sets: hand-worked GOSPA values, status filter, truths of another time, runs merged, the run result's codec, parameter refusals.
#include <trackflow/error.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "scoring/track_set_fixture.hpp"

using namespace trackflow;

using test::metric;
using test::one_run;
using test::step;
using test::track;
using test::truth;

namespace {

std::shared_ptr<Component> make(const std::string& yaml) { return test::make_track_set_sink("sink.gospa", yaml); }

}  // namespace

TEST_CASE("one truth and one track closer than c: GOSPA is d") {
  auto s = make("{ cutoff: 10 m }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(3, 4, 0))});
  CHECK(metric(sum, "gospa") == Approx(5.0));
  CHECK(metric(sum, "gospa_localisation") == Approx(25.0));
  CHECK(metric(sum, "gospa_missed") == 0.0);
  CHECK(metric(sum, "gospa_false") == 0.0);
  CHECK(metric(sum, "ospa") == Approx(5.0));
  CHECK(metric(sum, "missed_targets") == 0.0);
}

TEST_CASE("a missed target costs (c^p / 2)^(1/p)") {
  auto s = make("{ cutoff: 10 m, order: 3 }");
  const Summary sum = one_run(*s, {Vec3(1, 2, 3)}, {});
  CHECK(metric(sum, "gospa") == Approx(std::cbrt(500.0)));
  CHECK(metric(sum, "gospa_missed") == Approx(500.0));
  CHECK(metric(sum, "missed_targets") == 1.0);
  CHECK(metric(sum, "false_tracks") == 0.0);
  CHECK(metric(sum, "ospa") == Approx(10.0));
}

TEST_CASE("a far track is one missed and one false target") {
  auto s = make("{ cutoff: 10 m }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(100, 0, 0))});
  CHECK(metric(sum, "gospa") == Approx(10.0));
  CHECK(metric(sum, "gospa_missed") == Approx(50.0));
  CHECK(metric(sum, "gospa_false") == Approx(50.0));
  CHECK(metric(sum, "false_tracks") == 1.0);
  CHECK(metric(sum, "missed_targets") == 1.0);
}

TEST_CASE("tentative and deleted tracks are not scored by default") {
  auto s = make("{ cutoff: 10 m }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)},
                              {track(1, Vec3(3, 4, 0)), track(2, Vec3(0, 1, 0), TrackStatus::Tentative),
                               track(3, Vec3(0, 0, 0), TrackStatus::Deleted)});
  CHECK(metric(sum, "gospa") == Approx(5.0));
  CHECK(metric(sum, "tracks") == 1.0);
  auto t = make("{ cutoff: 10 m, statuses: 'tentative, confirmed' }");
  const Summary sum2 = one_run(*t, {Vec3(0, 0, 0)},
                               {track(1, Vec3(3, 4, 0)), track(2, Vec3(0, 1, 0), TrackStatus::Tentative)});
  // The tentative track at 1 m takes the truth; the other is false: (1 + 50)^(1/2).
  CHECK(metric(sum2, "gospa") == Approx(std::sqrt(51.0)));
  CHECK(metric(sum2, "false_tracks") == 1.0);
}

TEST_CASE("truths of another time are not used") {
  auto s = make("{ cutoff: 10 m }");
  test::start_run(*s);
  s->on_truth(truth(0.5, 0, Vec3(0, 0, 0)), 1);  // no set at 0.5 s
  const std::vector<TrackEstimate> tracks{track(1, Vec3(3, 4, 0))};
  s->on_tracks(TrackSet{1.0, tracks}, 0);  // scored against no truth: one false track
  auto r = s->end_run();
  s->merge(*r);
  Summary sum;
  s->finish(sum, {});
  CHECK(metric(sum, "gospa") == Approx(std::sqrt(50.0)));
  CHECK(metric(sum, "unscored_truth_steps") == 1.0);
  CHECK(metric(sum, "steps_without_truth") == 1.0);
}

TEST_CASE("planar scoring ignores z and skips non-finite tracks") {
  auto s = make("{ cutoff: 10 m, dimensions: 2 }");
  Vec3 bad(std::nan(""), 0, 0);
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(3, 4, 50)), track(2, bad)});
  CHECK(metric(sum, "gospa") == Approx(5.0));
  CHECK(metric(sum, "non_finite_tracks") == 1.0);
}

TEST_CASE("merged runs give the mean of the runs, and a series") {
  auto s = make("{ cutoff: 10 m }");
  for (int run = 0; run < 2; ++run) {
    test::start_run(*s, run);
    step(*s, 1.0, {Vec3(0, 0, 0)}, {track(1, Vec3(run ? 6 : 3, run ? 8 : 4, 0))});  // d = 5, 10 (not < c: 10)
    step(*s, 2.0, {Vec3(0, 0, 0)}, {track(1, Vec3(1, 0, 0))});                      // d = 1
    auto r = s->end_run();
    s->merge(*r);
  }
  Summary sum;
  s->finish(sum, {});
  CHECK(metric(sum, "gospa") == Approx((3.0 + 5.5) / 2.0));
  CHECK(metric(sum, "runs_scored") == 2.0);
  CHECK(metric(sum, "gospa_ci95_lo") < metric(sum, "gospa"));
  REQUIRE(sum.series.size() == 1);
  const Series& ser = sum.series[0];
  REQUIRE(ser.rows() == 2);
  CHECK(ser.at(0, ser.column("gospa")) == Approx(7.5));
  CHECK(ser.at(0, ser.column("gospa_missed")) == Approx(25.0));
  CHECK(ser.at(1, ser.column("gospa")) == Approx(1.0));
}

TEST_CASE("alpha other than 2: no parts, and no NaN in the series") {
  auto s = make("{ cutoff: 10 m, alpha: 1 }");
  test::start_run(*s);
  step(*s, 1.0, {Vec3(0, 0, 0)}, {});  // one missed target: d = (c^p / alpha)^(1/p) = 10
  auto r = s->end_run();
  s->merge(*r);
  Summary sum;
  s->finish(sum, {});
  CHECK(metric(sum, "gospa") == Approx(10.0));
  CHECK(sum.find("gospa_missed") == nullptr);
  REQUIRE(sum.series.size() == 1);
  const Series& ser = sum.series[0];
  for (const auto& c : ser.columns) CHECK(c.name != "gospa_missed");
  for (double v : ser.values) CHECK(std::isfinite(v));
  CHECK(ser.values.size() == ser.columns.size() * ser.rows());
}

TEST_CASE("the run result survives the codec") {
  test::check_codec_round_trip([] { return make("{ cutoff: 10 m }"); }, [](Component& s, int run) {
    step(s, 1.0, {Vec3(0, 0, 0), Vec3(20, 0, 0)}, {track(1, Vec3(run, 1, 0))});
  });
}

TEST_CASE("bad parameters are refused by name") {
  auto refused = [](const std::string& yaml, const std::string& name) { test::check_refused("sink.gospa", yaml, name); };
  refused("{ cutoff: 0 m }", "cutoff");
  refused("{ cutoff: 1 m, order: 0.5 }", "order");
  refused("{ cutoff: 1 m, alpha: 3 }", "alpha");
  refused("{ cutoff: 1 m, dimensions: 4 }", "dimensions");
  refused("{ cutoff: 1 m, statuses: deleted }", "statuses");
  refused("{ cutoff: 1 m, statuses: lost }", "statuses");
  refused("{}", "cutoff");
}
