// Purpose: tests of sink.track_quality on hand-made truths and track sets: perfect tracking, an identity swap, a break, establishment time, a spurious track, merged runs and the codec, parameter refusals.
#include <trackflow/error.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "scoring/track_set_fixture.hpp"

using namespace trackflow;

using test::metric;
using test::track;

namespace {

std::shared_ptr<Component> make(const std::string& yaml = "{ cutoff: 5 m }") {
  return test::make_track_set_sink("sink.track_quality", yaml);
}

Summary finish(Component& s) { return test::finish_run(s); }

// One step: truths (id = index unless given), then the track set.
void step(Component& s, double time, const std::vector<Vec3>& truths, const std::vector<TrackEstimate>& tracks,
          const std::vector<std::uint32_t>& ids = {}) {
  for (std::size_t i = 0; i < truths.size(); ++i) {
    Truth t;
    t.time = time;
    t.target = ids.empty() ? static_cast<std::uint32_t>(i) : ids[i];
    t.position = truths[i];
    s.on_truth(t, 1);
  }
  s.on_tracks(TrackSet{time, tracks}, 0);
}

const Vec3 A(0, 0, 0), B(100, 0, 0);

}  // namespace

TEST_CASE("followed throughout: complete, no swap or break") {
  auto s = make();
  test::start_run(*s);
  for (int k = 0; k < 4; ++k) step(*s, k, {A, B}, {track(1, A + Vec3(1, 0, 0)), track(2, B)});
  const Summary sum = finish(*s);
  CHECK(metric(sum, "completeness") == 1.0);
  CHECK(metric(sum, "spuriousness") == 0.0);
  CHECK(metric(sum, "id_swaps_per_run") == 0.0);
  CHECK(metric(sum, "track_breaks_per_run") == 0.0);
  CHECK(metric(sum, "establishment_time") == 0.0);
  CHECK(metric(sum, "targets_per_run") == 2.0);
  CHECK(metric(sum, "tracks_per_run") == 2.0);
  CHECK(metric(sum, "tracks_never_on_a_target") == 0.0);
}

TEST_CASE("tracks exchanging targets: one swap per truth") {
  auto s = make();
  test::start_run(*s);
  step(*s, 0, {A, B}, {track(1, A), track(2, B)});
  step(*s, 1, {A, B}, {track(1, B), track(2, A)});  // swapped
  step(*s, 2, {A, B}, {track(1, B), track(2, A)});  // stays swapped: no new swap
  const Summary sum = finish(*s);
  CHECK(metric(sum, "id_swaps_per_run") == 2.0);
  CHECK(metric(sum, "completeness") == 1.0);
}

TEST_CASE("a gap is a break, a new track a swap") {
  auto s = make();
  test::start_run(*s);
  step(*s, 0, {A}, {track(1, A)});
  step(*s, 1, {A}, {track(1, A + Vec3(6, 0, 0))});  // 6 m > c = 5 m: not followed, and spurious
  step(*s, 2, {A}, {track(1, A)});
  step(*s, 3, {A}, {track(3, A)});  // another track takes over: a swap
  const Summary sum = finish(*s);
  CHECK(metric(sum, "track_breaks_per_run") == 1.0);
  CHECK(metric(sum, "id_swaps_per_run") == 1.0);
  CHECK(metric(sum, "completeness") == Approx(0.75));
  CHECK(metric(sum, "spuriousness") == Approx(0.25));
}

TEST_CASE("establishment time, never-established, spurious") {
  auto s = make();
  test::start_run(*s);
  step(*s, 0, {A, B}, {track(7, Vec3(500, 0, 0))});
  step(*s, 1, {A, B}, {track(7, Vec3(500, 0, 0))});
  step(*s, 2.5, {A, B}, {track(7, Vec3(500, 0, 0)), track(8, A)});  // A established after 2.5 s; B never
  const Summary sum = finish(*s);
  CHECK(metric(sum, "establishment_time") == Approx(2.5));
  CHECK(metric(sum, "targets_established") == Approx(0.5));
  CHECK(metric(sum, "tracks_never_on_a_target") == Approx(0.5));  // track 7 of tracks 7 and 8
  CHECK(metric(sum, "spuriousness") == Approx(3.0 / 4.0));
  CHECK(metric(sum, "completeness") == Approx(1.0 / 6.0));
}

TEST_CASE("tentative tracks unscored, a set without truth") {
  auto s = make();
  test::start_run(*s);
  step(*s, 0, {A}, {track(1, A, TrackStatus::Tentative)});
  s->on_tracks(TrackSet{1.0, {}}, 0);
  const Summary sum = finish(*s);
  CHECK(metric(sum, "completeness") == 0.0);
  CHECK(metric(sum, "steps_without_truth") == 1.0);
}

TEST_CASE("merged runs pool their sums, codec round trip") {
  auto s = make(), direct = make(), decoded = make();
  const auto& codec = dynamic_cast<const RunResultCodec&>(*s);
  for (int run = 0; run < 3; ++run) {
    test::start_run(*s, run);
    step(*s, 0, {A, B}, {track(1, A), track(2, B + Vec3(run * 3.0, 0, 0))});  // run 2: B at 6 m, unfollowed
    step(*s, 1, {A, B}, {track(2, A), track(1, B)});
    auto r = s->end_run();
    std::string bytes;
    ByteWriter w(bytes);
    codec.save_run_result(*r, w);
    ByteReader in(bytes.data(), bytes.size());
    auto back = dynamic_cast<const RunResultCodec&>(*decoded).load_run_result(in);
    CHECK(in.done());
    direct->merge(*r);
    decoded->merge(*back);
  }
  Summary a, b;
  direct->finish(a, {});
  decoded->finish(b, {});
  REQUIRE(a.metrics.size() == b.metrics.size());
  for (std::size_t i = 0; i < a.metrics.size(); ++i) CHECK(a.metrics[i].value == b.metrics[i].value);
  CHECK(metric(a, "completeness") == Approx(11.0 / 12.0));
  CHECK(metric(a, "id_swaps_per_run") == Approx(5.0 / 3.0));  // 2, 2 and 1 (B unfollowed at step 0 of run 2)
}

TEST_CASE("bad parameters are refused by name") {
  CHECK_THROWS_AS(make("{ }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 5 m, dimensions: 4 }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 5 m, statuses: deleted }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 0 m }"), ConfigError);
}
