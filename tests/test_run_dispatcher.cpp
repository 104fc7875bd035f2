// Purpose: tests of the run dispatcher over a fake transport: run-order merge of out-of-order results, the window bound, failure by lowest run, progress.
#include "run_dispatcher.hpp"

#include <trackflow/error.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <random>
#include <set>
#include <thread>

using namespace trackflow;
using namespace trackflow::host;

namespace {

RunRecord record_of(std::uint64_t run) {
  RunRecord rec;
  rec.source_items = 1000 + run;  // the merge checks that each run's own record arrives
  return rec;
}

// What the dispatcher merged, in the order it merged it.
struct Merged {
  std::vector<std::uint64_t> runs;
  std::vector<std::uint64_t> items;
  RunDispatcher::MergeRun merge() {
    return [this](std::uint64_t run, RunRecord&& rec) {
      runs.push_back(run);
      items.push_back(rec.source_items);
    };
  }
};

std::vector<std::uint64_t> iota_runs(std::uint64_t n) {
  std::vector<std::uint64_t> v(n);
  for (std::uint64_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

// A transport on the calling thread: takes every run the window allows, then finishes one of
// those in flight chosen by a seeded shuffle (so runs finish out of order), failing the runs in
// `failing` in the order they finish. Records how far ahead of the oldest unmerged run it was given runs.
class FakeTransport final : public Transport {
 public:
  explicit FakeTransport(std::uint64_t window, unsigned seed = 1) : window_(window), rng_(seed) {}
  std::set<std::uint64_t> failing;
  std::vector<std::uint64_t> finish_order;
  std::uint64_t max_ahead = 0;      // largest (run handed out - runs merged then) + 1
  std::uint64_t refused_full = 0;   // take() calls that gave nothing while runs were in flight
  std::uint64_t taken_after_failure = 0;

  std::uint64_t window(std::vector<std::string>&) override { return window_; }

  void carry(RunDispatcher& d) override {
    std::vector<std::uint64_t> in_flight;
    for (;;) {
      const bool had_failed = d.has_failed();
      const std::uint64_t merged = d.merged();
      for (std::uint64_t run : d.take(1000)) {
        max_ahead = std::max(max_ahead, run - merged + 1);
        in_flight.push_back(run);
        if (had_failed) ++taken_after_failure;
      }
      if (in_flight.empty()) break;
      if (d.take(1).size() == 0 && !d.exhausted()) ++refused_full;
      std::uniform_int_distribution<std::size_t> pick(0, in_flight.size() - 1);
      const std::size_t i = pick(rng_);
      const std::uint64_t run = in_flight[i];
      in_flight.erase(in_flight.begin() + static_cast<std::ptrdiff_t>(i));
      finish_order.push_back(run);
      if (failing.count(run))
        d.failed_elsewhere(run, std::make_exception_ptr(DataError("run " + std::to_string(run) + ": node 'boom' failed")));
      else
        d.complete(run, record_of(run));
    }
  }

 private:
  const std::uint64_t window_;
  std::mt19937 rng_;
};

std::string message_of(RunDispatcher& d) {
  try {
    d.conclude();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("results finishing out of order are merged in run order") {
  std::vector<std::string> warnings;
  Merged merged;
  RunDispatcher d(40, 6, merged.merge(), nullptr, nullptr, warnings);
  FakeTransport t(6);
  t.carry(d);
  REQUIRE_NOTHROW(d.conclude());
  CHECK(t.finish_order != iota_runs(40));  // the fake really finished runs out of order
  CHECK(merged.runs == iota_runs(40));
  std::vector<std::uint64_t> items;
  for (std::uint64_t r = 0; r < 40; ++r) items.push_back(1000 + r);
  CHECK(merged.items == items);  // each run merged with its own record
  CHECK(d.merged() == 40);
  CHECK(d.completed() == 40);
}

TEST_CASE("the window bound is reached and never passed") {
  for (std::uint64_t window : {1u, 3u, 8u}) {
    std::vector<std::string> warnings;
    Merged merged;
    RunDispatcher d(60, window, merged.merge(), nullptr, nullptr, warnings);
    FakeTransport t(window, static_cast<unsigned>(window));
    t.carry(d);
    REQUIRE_NOTHROW(d.conclude());
    CHECK(t.max_ahead == window);  // the bound is reached, never passed
    CHECK(t.refused_full > 0);     // a full window gives nothing until a merge moves it
    CHECK(merged.runs == iota_runs(60));
  }
  SECTION("a window beyond the end hands out every run at once") {
    std::vector<std::string> warnings;
    Merged merged;
    RunDispatcher d(5, 999999999999ull, merged.merge(), nullptr, nullptr, warnings);
    CHECK(d.take(100) == iota_runs(5));
    CHECK(d.exhausted());
  }
}

TEST_CASE("a failing run stops the hand-out and is the one reported") {
  std::vector<std::string> warnings;
  Merged merged;
  RunDispatcher d(30, 5, merged.merge(), nullptr, nullptr, warnings);
  FakeTransport t(5, 7);
  t.failing = {12, 14};
  t.carry(d);
  CHECK(d.has_failed());
  CHECK(d.exhausted());
  CHECK(t.taken_after_failure == 0);
  CHECK(merged.runs == iota_runs(12));  // everything before run 12, nothing from it on
  // Both failed (whichever finished first): the lowest run is reported, with its node.
  CHECK(message_of(d) == "run 12: node 'boom' failed");
}

TEST_CASE("the lowest failure wins and a set-up failure before it") {
  std::vector<std::string> warnings;
  Merged merged;
  RunDispatcher d(10, 10, merged.merge(), nullptr, nullptr, warnings);
  REQUIRE(d.take(10) == iota_runs(10));
  d.failed_elsewhere(6, std::make_exception_ptr(DataError("run 6")));
  d.failed_elsewhere(3, std::make_exception_ptr(DataError("run 3")));
  d.failed_elsewhere(8, std::make_exception_ptr(DataError("run 8")));
  CHECK(message_of(d) == "run 3");
  d.failed_elsewhere(std::nullopt, std::make_exception_ptr(ConfigError("set-up")));
  d.failed_elsewhere(0, std::make_exception_ptr(DataError("run 0")));
  CHECK(message_of(d) == "set-up");
}

TEST_CASE("a merge failure names the run merged not the run finished") {
  std::vector<std::string> warnings;
  std::vector<std::uint64_t> merged;
  std::vector<std::optional<std::uint64_t>> attributed;
  auto merge = [&](std::uint64_t run, RunRecord&&) {
    if (run == 5) throw DataError("merge of run 5");
    merged.push_back(run);
  };
  auto attribute = [&](std::optional<std::uint64_t> run, std::exception_ptr e) {
    attributed.push_back(run);
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& x) {
      return std::make_exception_ptr(DataError(std::string("here: ") + x.what()));
    }
  };
  RunDispatcher d(10, 10, merge, nullptr, attribute, warnings);
  REQUIRE(d.take(10) == iota_runs(10));
  for (std::uint64_t r : {5, 6, 0, 1, 2, 3}) d.complete(r, record_of(r));
  CHECK(attributed.empty());
  d.complete(4, record_of(4));  // merges 4, then 5 throws
  CHECK(attributed == std::vector<std::optional<std::uint64_t>>{5});
  CHECK(d.waiting() == 0);  // 6 was waiting: dropped with the failed merge
  d.complete(7, record_of(7));
  CHECK(d.waiting() == 0);  // after the failure: dropped, not kept
  CHECK(merged == iota_runs(5));
  CHECK(message_of(d) == "here: merge of run 5");
  // A failure from another process is not attributed again.
  d.failed_elsewhere(2, std::make_exception_ptr(DataError("elsewhere")));
  CHECK(attributed.size() == 1);
  CHECK(message_of(d) == "elsewhere");
}

TEST_CASE("progress counts finished runs and ends at the total") {
  std::vector<std::string> warnings;
  Merged merged;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> shown;
  RunDispatcher d(6, 6, merged.merge(), [&](std::uint64_t done, std::uint64_t total) { shown.emplace_back(done, total); },
                  nullptr, warnings);
  REQUIRE(d.take(6) == iota_runs(6));
  d.complete(2, record_of(2));
  d.complete(0, record_of(0));
  d.complete(5, record_of(5));
  d.show_progress();
  REQUIRE(shown.size() == 1);
  CHECK(shown[0] == std::make_pair<std::uint64_t, std::uint64_t>(3, 6));  // finished, merged or not
  CHECK(d.merged() == 1);
  d.show_progress();  // at most every 100 ms
  CHECK(shown.size() == 1);
  for (std::uint64_t r : {1, 3, 4}) d.complete(r, record_of(r));
  d.conclude();
  CHECK(shown.back() == std::make_pair<std::uint64_t, std::uint64_t>(6, 6));
  SECTION("no final progress after a failure") {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> after;
    RunDispatcher f(2, 2, merged.merge(), [&](std::uint64_t a, std::uint64_t b) { after.emplace_back(a, b); }, nullptr,
                    warnings);
    REQUIRE(f.take(2) == iota_runs(2));
    f.failed_elsewhere(1, std::make_exception_ptr(DataError("x")));
    f.complete(0, record_of(0));
    f.show_progress();
    CHECK_THROWS_AS(f.conclude(), DataError);
    CHECK(after.empty());
  }
}

TEST_CASE("threads waiting on the window merge every run in order") {
  std::vector<std::string> warnings;
  Merged merged;
  constexpr std::uint64_t kRuns = 300;
  RunDispatcher d(kRuns, 3, merged.merge(), nullptr, nullptr, warnings);
  std::atomic<int> beyond_window{0};
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < 4; ++t)
    threads.emplace_back([&d, &beyond_window, t] {
      std::mt19937 rng(t);
      while (const auto run = d.next_run()) {
        // merged() only grows: a run handed out within the window is still below merged() + 3.
        if (*run >= d.merged() + 3) ++beyond_window;
        std::this_thread::sleep_for(std::chrono::microseconds(rng() % 200));
        d.finished(*run, record_of(*run), GraphInstance{});
      }
    });
  for (auto& th : threads) th.join();
  REQUIRE_NOTHROW(d.conclude());
  CHECK(merged.runs == iota_runs(kRuns));
  CHECK(beyond_window.load() == 0);
}
