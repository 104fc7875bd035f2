// Purpose: run_graph — the Monte Carlo ensemble on this process's threads: the local-threads transport of the run dispatcher.
#include <trackflow/host/engine.hpp>

#include "run_dispatcher.hpp"
#include "worker_pool.hpp"

#include <algorithm>

namespace trackflow::host {
namespace {

// Runs go to `threads` worker threads of this process; failures are reported as they were raised
// (rethrow_from_plugin names the run and the node already).
class LocalThreads final : public Transport {
 public:
  LocalThreads(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, unsigned threads)
      : g_(g), registry_(registry), opt_(opt), threads_(threads) {}

  // Four runs per thread: enough that no thread waits for a merge, few enough that finished runs
  // (a sink's rows) do not pile up behind a slow one.
  std::uint64_t window(std::vector<std::string>&) override { return 4 * static_cast<std::uint64_t>(threads_); }

  void carry(RunDispatcher& d) override {
    WorkerPool pool(g_, registry_, opt_, d);
    // One thread and nothing to show: the calling thread does the work (a sweep runs many
    // ensembles side by side; a thread each is enough).
    if (threads_ == 1 && !opt_.progress) return pool.work();
    // A per-user process limit: go on with the workers that started, or on this thread if none did.
    if (const std::string short_of_threads = pool.start(threads_); !short_of_threads.empty()) {
      d.warn(short_of_threads);
      if (!pool.running()) pool.work();
    }
    if (opt_.progress)
      while (pool.running()) {
        d.show_progress();
        d.wait_for_change(std::chrono::milliseconds(100));
      }
    pool.join();
  }

 private:
  const Graph& g_;
  const PluginRegistry& registry_;
  const RunOptions& opt_;
  const unsigned threads_;
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
  // The aggregating instance is built first so construction errors surface before any thread starts.
  GraphInstance aggregate = instantiate(g, registry);
  LocalThreads transport(g, registry, opt, threads);
  return dispatch_ensemble(g, aggregate, opt, runs, transport);
}

}  // namespace trackflow::host
