// Purpose: what the tests of the track-set sinks (sink.gospa, sink.ospa) feed them: hand-made tracks and truths, one scan's step, one whole run, a metric by name.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "plugin_fixture.hpp"

namespace trackflow::test {

inline TrackEstimate track(std::uint64_t id, Vec3 p, TrackStatus st = TrackStatus::Confirmed) {
  TrackEstimate t;
  t.id = id;
  t.status = st;
  t.estimate.initialised = true;
  t.estimate.enu.setZero();
  t.estimate.enu.head<3>() = p;
  return t;
}

inline Truth truth(double time, std::uint32_t id, Vec3 p) {
  Truth t;
  t.time = time;
  t.target = id;
  t.position = p;
  return t;
}

// A track-set sink of `type` with its inputs set: a tracker's track sets and a scenario's truth.
inline std::shared_ptr<Component> make_track_set_sink(const std::string& type, const std::string& yaml) {
  auto s = make(type, yaml);
  s->set_inputs({{"tracker", "tracker.multi", mask(ItemKind::Tracks), {}},
                 {"scenario", "sim.scenario", mask(ItemKind::Truth), {}}});
  return s;
}

// One step: the truths (ids 0, 1, ...), then the set.
inline void step(Component& s, double time, const std::vector<Vec3>& truths, const std::vector<TrackEstimate>& tracks) {
  for (std::size_t i = 0; i < truths.size(); ++i) s.on_truth(truth(time, static_cast<std::uint32_t>(i), truths[i]), 1);
  s.on_tracks(TrackSet{time, tracks}, 0);
}

// The value of metric `name`, or -1 when there is none.
inline double metric(const Summary& s, const std::string& name) {
  const Metric* m = s.find(name);
  return m ? m->value : -1.0;
}

// The run in progress ended and merged, and the summary of all runs merged so far.
inline Summary finish_run(Component& s) {
  auto r = s.end_run();
  s.merge(*r);
  Summary sum;
  s.finish(sum, {});
  return sum;
}

// One run of one step at t = 1 s.
inline Summary one_run(Component& s, const std::vector<Vec3>& truths, const std::vector<TrackEstimate>& tracks) {
  start_run(s);
  step(s, 1.0, truths, tracks);
  return finish_run(s);
}

// `r` written by `from`'s codec and read back by `to`'s, all bytes read.
inline std::unique_ptr<RunResult> through_codec(const Component& from, const Component& to, const RunResult& r) {
  std::string bytes;
  ByteWriter w(bytes);
  dynamic_cast<const RunResultCodec&>(from).save_run_result(r, w);
  ByteReader in(bytes.data(), bytes.size());
  auto back = dynamic_cast<const RunResultCodec&>(to).load_run_result(in);
  CHECK(in.done());
  return back;
}

// The same metrics bit for bit, and the same series.
inline void check_same_summary(const Summary& a, const Summary& b) {
  REQUIRE(a.metrics.size() == b.metrics.size());
  for (std::size_t i = 0; i < a.metrics.size(); ++i) {
    CHECK(a.metrics[i].name == b.metrics[i].name);
    CHECK(std::memcmp(&a.metrics[i].value, &b.metrics[i].value, sizeof(double)) == 0);
  }
  REQUIRE(a.series.size() == b.series.size());
  for (std::size_t i = 0; i < a.series.size(); ++i) CHECK(a.series[i].values == b.series[i].values);
}

// Creating a `type` node with parameters `yaml` fails with a ConfigError that names `name`.
inline void check_refused(const std::string& type, const std::string& yaml, const std::string& name) {
  try {
    make(type, yaml);
  } catch (const ConfigError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains(name));
    return;
  }
  FAIL("accepted: " << yaml);
}

// `runs` runs of feed(sink, run) on one sink made by make(); each run's result is merged into a
// second sink as it is and into a third after the codec: both summaries must be the same.
template <class Make, class Feed>
void check_codec_round_trip(Make make, Feed feed, int runs = 3) {
  auto s = make(), direct = make(), decoded = make();
  for (int run = 0; run < runs; ++run) {
    start_run(*s, static_cast<std::uint64_t>(run));
    feed(*s, run);
    auto r = s->end_run();
    if (!r) continue;  // a sink that records one run only
    auto back = through_codec(*s, *decoded, *r);
    direct->merge(*r);
    decoded->merge(*back);
  }
  Summary a, b;
  direct->finish(a, {});
  decoded->finish(b, {});
  check_same_summary(a, b);
}

}  // namespace trackflow::test
