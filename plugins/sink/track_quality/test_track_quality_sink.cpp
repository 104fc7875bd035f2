// Purpose: tests of sink.track_quality on hand-made truths and track sets: perfect tracking, an identity swap, a break, establishment time, a spurious track, SIAP position and velocity accuracy, merged runs and the codec, parameter refusals.
#include <trackflow/error.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
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

// A track at p moving with v (the Estimate's enu block [x y z vx vy vz]).
TrackEstimate moving(std::uint64_t id, Vec3 p, Vec3 v) {
  TrackEstimate t = track(id, p);
  t.estimate.enu.tail<3>() = v;
  return t;
}

struct Moving {
  Vec3 p, v;
};

// One step of truths with velocities (ids 0, 1, ...), then the track set.
void step_moving(Component& s, double time, const std::vector<Moving>& truths, const std::vector<TrackEstimate>& tracks) {
  for (std::size_t i = 0; i < truths.size(); ++i) {
    Truth t = test::truth(time, static_cast<std::uint32_t>(i), truths[i].p);
    t.velocity = truths[i].v;
    s.on_truth(t, 1);
  }
  s.on_tracks(TrackSet{time, tracks}, 0);
}

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

// SIAP accuracy: over all pairs of all steps, PA = sum |track - truth| / pairs, VA the same of the
// velocities; RMS = sqrt(sum of squares / pairs).
TEST_CASE("SIAP accuracy: mean and RMS over the pairs") {
  auto s = make();  // c = 5 m, 3-D
  test::start_run(*s);
  const Vec3 va(10, 0, 0), vb(0, 10, 0);
  // Step 0: track 1 off A by (1, 2, 2): 3 m, velocity off by (0, 3, 4): 5 m/s; track 2 off B by
  // (0, 0, 4): 4 m, velocity exact: 0 m/s.
  step_moving(*s, 0, {{A, va}, {B, vb}},
              {moving(1, A + Vec3(1, 2, 2), va + Vec3(0, 3, 4)), moving(2, B + Vec3(0, 0, 4), vb)});
  // Step 1: track 1 on A (0 m), velocity off by (2, 1, 2): 3 m/s; track 2 12 m off B: no pair.
  step_moving(*s, 1, {{A, va}, {B, vb}}, {moving(1, A, va + Vec3(2, 1, 2)), moving(2, B + Vec3(12, 0, 0), vb)});
  const Summary sum = finish(*s);
  CHECK(metric(sum, "completeness") == 0.75);  // 3 pairs of 4 truth-steps
  // Position errors 3, 4, 0 m: mean 7/3 = 2.3333 m, RMS sqrt((9 + 16 + 0) / 3) = sqrt(25/3) = 2.8868 m.
  CHECK(metric(sum, "position_accuracy") == Approx(7.0 / 3.0).epsilon(1e-14));
  CHECK(metric(sum, "position_accuracy_rms") == Approx(2.886751345948129).epsilon(1e-14));
  // Velocity errors 5, 0, 3 m/s: mean 8/3 = 2.6667 m/s, RMS sqrt((25 + 0 + 9) / 3) = sqrt(34/3) = 3.3665 m/s.
  CHECK(metric(sum, "velocity_accuracy") == Approx(8.0 / 3.0).epsilon(1e-14));
  CHECK(metric(sum, "velocity_accuracy_rms") == Approx(3.366501646120693).epsilon(1e-14));
  REQUIRE(sum.find("position_accuracy") != nullptr);
  CHECK(sum.find("position_accuracy")->unit == "m");
  CHECK(sum.find("velocity_accuracy")->unit == "m/s");
}

TEST_CASE("SIAP accuracy planar: x-y errors only") {
  // z is 100 m off: dimensions 2 pairs the track (x-y distance 3 m < 5 m) and ignores z and vz.
  auto planar = make("{ cutoff: 5 m, dimensions: 2 }");
  test::start_run(*planar);
  // Step 0: position off by (3, 0, 100): 3 m in x-y; velocity off by (0, 4, 50): 4 m/s in x-y.
  step_moving(*planar, 0, {{A, Vec3::Zero()}}, {moving(1, Vec3(3, 0, 100), Vec3(0, 4, 50))});
  // Step 1: position off by (0, 4, -7): 4 m; velocity off by (3, 0, 0): 3 m/s.
  step_moving(*planar, 1, {{A, Vec3::Zero()}}, {moving(1, Vec3(0, 4, -7), Vec3(3, 0, 0))});
  const Summary sum = finish(*planar);
  // Mean (3 + 4) / 2 = 3.5 for both, RMS sqrt((9 + 16) / 2) = sqrt(12.5) = 3.5355.
  CHECK(metric(sum, "position_accuracy") == 3.5);
  CHECK(metric(sum, "velocity_accuracy") == 3.5);
  CHECK(metric(sum, "position_accuracy_rms") == Approx(3.5355339059327378).epsilon(1e-14));
  CHECK(metric(sum, "velocity_accuracy_rms") == Approx(3.5355339059327378).epsilon(1e-14));

  // The same sets in 3-D: 100 m and 7 m off are beyond c = 5 m, no pair at all: no accuracy
  // published (no NaN), the other metrics as usual.
  auto spatial = make();
  test::start_run(*spatial);
  step_moving(*spatial, 0, {{A, Vec3::Zero()}}, {moving(1, Vec3(3, 0, 100), Vec3(0, 4, 50))});
  step_moving(*spatial, 1, {{A, Vec3::Zero()}}, {moving(1, Vec3(0, 4, -7), Vec3(3, 0, 0))});
  const Summary none = finish(*spatial);
  CHECK(none.find("position_accuracy") == nullptr);
  CHECK(none.find("position_accuracy_rms") == nullptr);
  CHECK(none.find("velocity_accuracy") == nullptr);
  CHECK(none.find("velocity_accuracy_rms") == nullptr);
  CHECK(metric(none, "completeness") == 0.0);
  for (const Metric& m : none.metrics) CHECK(std::isfinite(m.value));
}

TEST_CASE("SIAP accuracy: steps without pairs add nothing") {
  auto s = make();
  test::start_run(*s);
  step_moving(*s, 0, {{A, Vec3::Zero()}}, {moving(1, A + Vec3(0, 2, 0), Vec3(0, 0, 1))});  // 2 m, 1 m/s
  step_moving(*s, 1, {{A, Vec3::Zero()}}, {moving(1, A + Vec3(6, 0, 0), Vec3::Zero())});   // 6 m: no pair
  s->on_tracks(TrackSet{2.0, {}}, 0);                                                     // no truth, no track
  step_moving(*s, 3, {{A, Vec3::Zero()}}, {});                                            // a truth, no track
  const Summary sum = finish(*s);
  // One pair: the means are its errors, not diluted by the three steps without one.
  CHECK(metric(sum, "position_accuracy") == 2.0);
  CHECK(metric(sum, "position_accuracy_rms") == 2.0);
  CHECK(metric(sum, "velocity_accuracy") == 1.0);
  CHECK(metric(sum, "velocity_accuracy_rms") == 1.0);
  CHECK(metric(sum, "steps_without_truth") == 1.0);
}

TEST_CASE("SIAP accuracy: a non-finite track velocity") {
  auto s = make();
  test::start_run(*s);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Truth 0 paired at 1 m with a NaN velocity; truth 1 paired at 3 m, velocity off by 2 m/s.
  step_moving(*s, 0, {{A, Vec3::Zero()}, {B, Vec3::Zero()}},
              {moving(1, A + Vec3(1, 0, 0), Vec3(nan, 0, 0)), moving(2, B + Vec3(0, 3, 0), Vec3(0, 0, 2))});
  const Summary sum = finish(*s);
  CHECK(metric(sum, "position_accuracy") == 2.0);  // (1 + 3) / 2
  CHECK(metric(sum, "velocity_accuracy") == 2.0);  // the finite one only
  bool noted = false;
  for (const std::string& n : sum.notes) noted = noted || n.find("non-finite track velocity") != std::string::npos;
  CHECK(noted);
}

TEST_CASE("SIAP accuracy of merged runs pools the pairs") {
  auto s = make(), direct = make(), decoded = make();
  // Run 0: one pair, 1 m and 2 m/s off. Run 1: three pairs, each 3 m off, velocities exact.
  test::start_run(*s, 0);
  step_moving(*s, 0, {{A, Vec3::Zero()}}, {moving(1, A + Vec3(1, 0, 0), Vec3(0, 2, 0))});
  auto r0 = s->end_run();
  test::start_run(*s, 1);
  step_moving(*s, 0, {{A, Vec3::Zero()}, {B, Vec3::Zero()}},
              {moving(1, A + Vec3(3, 0, 0), Vec3::Zero()), moving(2, B + Vec3(0, 3, 0), Vec3::Zero())});
  step_moving(*s, 1, {{A, Vec3::Zero()}}, {moving(1, A + Vec3(0, 0, 3), Vec3::Zero())});
  auto r1 = s->end_run();
  for (RunResult* r : {r0.get(), r1.get()}) {
    direct->merge(*r);
    decoded->merge(*test::through_codec(*s, *decoded, *r));
  }
  Summary sum, back;
  direct->finish(sum, {});
  decoded->finish(back, {});
  test::check_same_summary(sum, back);
  // Pooled over the 4 pairs, not the mean of the run means (1 and 3 m: 2 m):
  // position (1 + 3 + 3 + 3) / 4 = 2.5 m, RMS sqrt((1 + 9 + 9 + 9) / 4) = sqrt(7) = 2.6458 m;
  // velocity (2 + 0 + 0 + 0) / 4 = 0.5 m/s, RMS sqrt(4 / 4) = 1 m/s.
  CHECK(metric(sum, "position_accuracy") == 2.5);
  CHECK(metric(sum, "position_accuracy_rms") == Approx(2.6457513110645907).epsilon(1e-14));
  CHECK(metric(sum, "velocity_accuracy") == 0.5);
  CHECK(metric(sum, "velocity_accuracy_rms") == 1.0);
}

TEST_CASE("bad parameters are refused by name") {
  CHECK_THROWS_AS(make("{ }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 5 m, dimensions: 4 }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 5 m, statuses: deleted }"), ConfigError);
  CHECK_THROWS_AS(make("{ cutoff: 0 m }"), ConfigError);
}
