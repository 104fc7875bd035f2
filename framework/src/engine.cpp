// Purpose: the run loop: time-ordered merge of sources, Monte Carlo runs on worker threads, ordered reduction.
#include <trackflow/host/engine.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/rng.hpp>

#include "run_one.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <queue>
#include <system_error>
#include <thread>

namespace trackflow::host {
namespace {

// Joins every started worker however the coordinating thread leaves (a std::thread destroyed
// while joinable would terminate the process).
struct Joiner {
  std::vector<std::thread>& pool;
  ~Joiner() {
    for (auto& t : pool)
      if (t.joinable()) t.join();
  }
};

}  // namespace

const NodeOutcome* Outcome::find(const std::string& id) const {
  for (const auto& n : nodes)
    if (n.id == id) return &n;
  return nullptr;
}

Outcome run_graph(const Graph& g, const PluginRegistry& registry, const RunOptions& opt) {
  const std::uint64_t runs = std::max<std::uint64_t>(1, opt.runs);
  const unsigned threads = static_cast<unsigned>(std::clamp<std::uint64_t>(opt.threads, 1, runs));
  std::atomic<std::uint64_t> next_run{0}, done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;

  Outcome out = empty_outcome(g, runs);

  // The aggregating instance is built first so construction errors surface before any thread starts.
  GraphInstance aggregate = instantiate(g, registry);
  const NodeLabels aggregate_labels = labels_of(g, aggregate);
  // Sinks that stream their files while runs are merged ask output_directory() on the thread
  // that merges: every thread of this ensemble answers with this run's --out.
  const std::string output_dir = opt.output_dir;

  // Finished runs wait here until every earlier run has been merged: merging happens strictly
  // in run order (so sums are identical for any thread count) and memory stays bounded by the
  // runs in flight, not the ensemble size.
  RunOrderMerge merger(aggregate, aggregate_labels, runs, out);
  std::mutex merge_mutex;
  // A worker does not start a run more than `window` runs ahead of the oldest unmerged one, so a
  // slow run cannot make finished ones (a sink's rows) pile up without bound.
  const std::uint64_t window = 4 * static_cast<std::uint64_t>(threads);
  std::condition_variable merged;
  auto complete = [&](std::uint64_t run, RunRecord&& rec) {
    std::lock_guard<std::mutex> lock(merge_mutex);
    merger.complete(run, std::move(rec));
    merged.notify_all();
  };
  auto wait_for_window = [&](std::uint64_t run) {
    std::unique_lock<std::mutex> lock(merge_mutex);
    merged.wait(lock, [&] { return run < merger.merged() + window || failed.load(); });
  };

  auto worker = [&]() {
    prepare_thread_for_crash_reports();
    OutputDirectoryScope dir(output_dir);
    try {
      Activity building{"building the graph for a worker"};
      ActivityScope building_scope(building);
      GraphInstance inst = instantiate(g, registry);
      const NodeLabels labels = labels_of(g, inst);
      Activity running{"running", &labels};
      ActivityScope running_scope(running);
      const std::vector<Filter*> filters = filters_of(inst);
      for (;;) {
        const std::uint64_t run = next_run.fetch_add(1);
        if (run >= runs || failed.load()) break;
        wait_for_window(run);
        if (failed.load()) break;
        running.run = run;
        running.has_run = true;
        RunRecord rec;
        try {
          rec = run_one(g, inst, filters, opt.seed, run);
          detail::executing = nullptr;
        } catch (...) {
          rethrow_from_plugin();  // names the run, the node and its plugin file
        }
        running.has_run = false;
        complete(run, std::move(rec));
        done.fetch_add(1);
      }
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(merge_mutex);
        failed = true;
      }
      merged.notify_all();
    }
  };

  const auto t0 = std::chrono::steady_clock::now();
  {
    std::vector<std::thread> pool;
    Joiner joiner{pool};
    try {
      // One thread and nothing to show: the calling thread does the work (a sweep runs many
      // ensembles side by side; a thread each is enough).
      if (threads == 1 && !opt.progress)
        worker();
      else
        for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
    } catch (const std::system_error& e) {
      // A per-user process limit: go on with the workers that started (results do not depend
      // on their number), or on this thread if none did.
      if (out.warnings.size() < 20)
        out.warnings.push_back("engine: started " + std::to_string(pool.size()) + " of " + std::to_string(threads) +
                               " worker threads (" + e.what() + "); results are the same with fewer");
      if (pool.empty()) worker();
    }
    if (opt.progress && !pool.empty()) {
      try {
        while (done.load() < runs && !failed.load()) {
          opt.progress(done.load(), runs);
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        if (!failed.load()) opt.progress(runs, runs);
      } catch (...) {
        // The progress display is cosmetic; the runs go on.
      }
    }
  }
  const auto t1 = std::chrono::steady_clock::now();
  if (error) std::rethrow_exception(error);
  out.seconds = std::chrono::duration<double>(t1 - t0).count();

  OutputDirectoryScope dir(output_dir);
  finish_all(g, aggregate, aggregate_labels, opt, runs, out);
  return out;
}

}  // namespace trackflow::host
