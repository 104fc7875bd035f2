// Purpose: worker threads that each build one instance of the graph and execute the runs a RunSource hands them — the local-threads transport of both engines.
#pragma once

#include "run_dispatcher.hpp"

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace trackflow::host {

// One instance of the graph on one thread, executing whole runs.
class RunExecutor {
 public:
  RunExecutor(const Graph& g, const PluginRegistry& registry, std::uint64_t seed);
  // Run `run` on this instance; an exception from plugin code names the run, the node and its
  // plugin file (rethrow_from_plugin).
  RunRecord run(std::uint64_t run);
  const GraphInstance& instance() const { return inst_; }

 private:
  const Graph& g_;
  const std::uint64_t seed_;
  GraphInstance inst_;
  std::vector<Filter*> filters_;
  NodeLabels labels_;
};

// Threads pulling runs from `source` until it has none. A thread that cannot build its
// instance reports that (failed without a run) and fails every run it is then given.
class WorkerPool {
 public:
  WorkerPool(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, RunSource& source)
      : g_(g), registry_(registry), opt_(opt), source_(source) {}
  ~WorkerPool() { join(); }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Starts `n` threads. Under a process limit fewer may start: returns the warning for the
  // summary (results do not depend on the number of threads), empty when all did.
  std::string start(unsigned n);
  // Executes runs on the calling thread until the source has none.
  void work();
  // Some started thread is still executing runs.
  bool running() const { return live_.load() > 0; }
  void join();

 private:
  const Graph& g_;
  const PluginRegistry& registry_;
  const RunOptions& opt_;
  RunSource& source_;
  std::vector<std::thread> threads_;
  std::atomic<unsigned> live_{0};
};

}  // namespace trackflow::host
