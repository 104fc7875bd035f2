// Purpose: tests of sink.mode_switch fed synthetic annotated estimates: steps counted by hand, runs that never switch, the window before, an unknown annotation refused.
#include <trackflow/error.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

// One run at 10 Hz for 5 s; the annotation (channel 1) is `value(k)`.
template <class Value>
void feed(Component& sink, std::uint64_t run, Value value) {
  Diagnostics d;
  sink.start_run({run, 1, &d});
  for (int k = 0; k < 50; ++k) {
    Estimate e;
    e.time = 0.1 * k;
    e.initialised = k >= 2;
    e.annotation_count = 2;
    e.annotations[0] = 0.0;
    e.annotations[1] = value(k);
    sink.on_estimate(e, 0);
  }
  std::unique_ptr<RunResult> result = sink.end_run();
  sink.merge(*result);
}

// A missing metric reads as -1, which no check below accepts.
double metric(const Summary& s, const std::string& name) {
  const Metric* m = s.find(name);
  return m ? m->value : -1.0;
}

std::vector<InputInfo> inputs() { return {{"imm", "filter.imm", mask(ItemKind::Estimate), {"imm.p_cv", "imm.p_ca"}}}; }

}  // namespace

TEST_CASE("steps to switch counted by hand over two runs") {
  auto sink = test::make("sink.mode_switch", "{ annotation: imm.p_ca, after: 2 s, before: 1 s }");
  sink->set_inputs(inputs());
  // Run 0: 0.1 until sample 23 (t = 2.3 s), then 0.9: 3 steps. Run 1: 0.2 until sample 21: 1 step.
  feed(*sink, 0, [](int k) { return k < 23 ? 0.1 : 0.9; });
  feed(*sink, 1, [](int k) { return k < 21 ? 0.2 : 0.9; });
  Summary s;
  sink->finish(s, {});
  CHECK(metric(s, "switched_fraction") == 1.0);
  CHECK(metric(s, "mean_steps") == Approx(2.0));
  CHECK(metric(s, "max_steps") == 3.0);
  CHECK(metric(s, "mean_before") == Approx(0.15));  // [1 s, 2 s): 10 samples of each run
}

TEST_CASE("a run that never switches lowers the fraction") {
  auto sink = test::make("sink.mode_switch", "{ annotation: imm.p_ca, after: 2 s }");
  sink->set_inputs(inputs());
  feed(*sink, 0, [](int) { return 0.4; });
  feed(*sink, 1, [](int k) { return k < 20 ? 0.4 : 0.6; });
  Summary s;
  sink->finish(s, {});
  CHECK(metric(s, "switched_fraction") == 0.5);
  CHECK(metric(s, "max_steps") == 30.0);  // samples 20..49
}

TEST_CASE("an annotation the filter does not publish is refused") {
  auto sink = test::make("sink.mode_switch", "{ annotation: imm.p_singer, after: 2 s }");
  CHECK_THROWS_AS(sink->set_inputs(inputs()), ConfigError);
}
