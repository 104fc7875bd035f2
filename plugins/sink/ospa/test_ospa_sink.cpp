// Purpose: tests of sink.ospa fed hand-made truths and track sets: hand-worked OSPA values and terms, status filter, runs merged with a series, the run result's codec, parameter refusals.
#include <trackflow/error.hpp>
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

namespace {

std::shared_ptr<Component> make(const std::string& yaml) { return test::make_track_set_sink("sink.ospa", yaml); }

}  // namespace

TEST_CASE("sink.ospa: one truth and one track closer than c") {
  auto s = make("{ cutoff: 10 m, order: 1 }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(3, 0, 0))});
  CHECK(metric(sum, "ospa") == Approx(3.0));
  CHECK(metric(sum, "ospa_localisation") == Approx(3.0));
  CHECK(metric(sum, "ospa_cardinality") == 0.0);
  CHECK(metric(sum, "truths") == 1.0);
  CHECK(metric(sum, "tracks") == 1.0);
}

TEST_CASE("sink.ospa: a false track costs c over n") {
  // X = {0}, Y = {0, 100}, c = 10, p = 1: (0 + 10) / 2.
  auto s = make("{ cutoff: 10 m, order: 1 }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(0, 0, 0)), track(2, Vec3(100, 0, 0))});
  CHECK(metric(sum, "ospa") == Approx(5.0));
  CHECK(metric(sum, "ospa_localisation") == 0.0);
  CHECK(metric(sum, "ospa_cardinality") == Approx(5.0));
}

TEST_CASE("sink.ospa: no tracks at all is c") {
  auto s = make("{ cutoff: 10 m, order: 3 }");
  const Summary sum = one_run(*s, {Vec3(1, 2, 3), Vec3(50, 0, 0)}, {});
  CHECK(metric(sum, "ospa") == Approx(10.0));
  CHECK(metric(sum, "ospa_pow_p") == Approx(1000.0));
  CHECK(metric(sum, "ospa_cardinality") == Approx(1000.0));
}

TEST_CASE("sink.ospa: tentative tracks are not scored by default") {
  auto s = make("{ cutoff: 10 m, order: 1 }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)},
                              {track(1, Vec3(3, 0, 0)), track(2, Vec3(0, 1, 0), TrackStatus::Tentative)});
  CHECK(metric(sum, "ospa") == Approx(3.0));
  CHECK(metric(sum, "tracks") == 1.0);
}

TEST_CASE("sink.ospa: planar scoring ignores z") {
  auto s = make("{ cutoff: 10 m, dimensions: 2 }");
  const Summary sum = one_run(*s, {Vec3(0, 0, 0)}, {track(1, Vec3(3, 4, 50))});
  CHECK(metric(sum, "ospa") == Approx(5.0));
}

TEST_CASE("sink.ospa: merged runs give the run means and a series") {
  auto s = make("{ cutoff: 10 m, order: 1 }");
  for (int run = 0; run < 2; ++run) {
    test::start_run(*s, run);
    step(*s, 1.0, {Vec3(0, 0, 0)}, {track(1, Vec3(run ? 6 : 2, 0, 0))});  // d = 2, 6
    step(*s, 2.0, {Vec3(0, 0, 0)}, {});                                    // c
    auto r = s->end_run();
    s->merge(*r);
  }
  Summary sum;
  s->finish(sum, {});
  CHECK(metric(sum, "ospa") == Approx(((2.0 + 10.0) / 2.0 + (6.0 + 10.0) / 2.0) / 2.0));
  CHECK(metric(sum, "runs_scored") == 2.0);
  CHECK(metric(sum, "scored_steps") == 4.0);
  CHECK(metric(sum, "ospa_ci95_lo") < metric(sum, "ospa"));
  CHECK(metric(sum, "ospa_ci95_hi") > metric(sum, "ospa"));
  REQUIRE(sum.series.size() == 1);
  const Series& ser = sum.series[0];
  CHECK(ser.name == "ospa");
  REQUIRE(ser.rows() == 2);
  CHECK(ser.at(0, ser.column("ospa")) == Approx(4.0));
  CHECK(ser.at(0, ser.column("runs")) == 2.0);
  CHECK(ser.at(1, ser.column("ospa_cardinality")) == Approx(10.0));
}

TEST_CASE("sink.ospa: the run result survives the codec") {
  test::check_codec_round_trip([] { return make("{ cutoff: 10 m }"); }, [](Component& s, int run) {
    step(s, 1.0, {Vec3(0, 0, 0), Vec3(20, 0, 0)}, {track(1, Vec3(run, 1, 0))});
    step(s, 2.0, {Vec3(0, 0, 0)}, {track(1, Vec3(0, run, 0)), track(2, Vec3(40, 0, 0))});
  });
}

TEST_CASE("sink.ospa: bad parameters are refused by name") {
  auto refused = [](const std::string& yaml, const std::string& name) { test::check_refused("sink.ospa", yaml, name); };
  refused("{ cutoff: 0 m }", "cutoff");
  refused("{ cutoff: 1 m, order: 0.5 }", "order");
  refused("{ cutoff: 1 m, dimensions: 4 }", "dimensions");
  refused("{ cutoff: 1 m, statuses: deleted }", "statuses");
  refused("{}", "cutoff");
}
