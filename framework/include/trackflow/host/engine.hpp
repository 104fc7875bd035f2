// Purpose: runs a checked graph once or as a Monte Carlo ensemble on several threads, deterministically.
#pragma once

#include <trackflow/host/graph.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace trackflow::host {

struct RunOptions {
  std::uint64_t runs = 1;
  unsigned threads = 1;
  std::uint64_t seed = 1;
  std::string output_dir = ".";
  // Called from the coordinating thread with (runs done, runs total) a few times a second.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

struct NodeOutcome {
  std::string id;
  std::string type;
  Summary summary;
  std::uint64_t skips = 0;
  std::vector<std::string> skip_examples;  // first few messages
};

struct Outcome {
  std::vector<NodeOutcome> nodes;  // in pipeline order
  std::vector<std::string> warnings;
  std::uint64_t runs = 0;
  std::uint64_t source_items = 0;  // items emitted by generators, all runs
  std::uint64_t measurements_processed = 0;  // measurements the filters published estimates for
  int filters = 0;
  double seconds = 0.0;            // wall time of the runs (not set-up, not reporting)
  const NodeOutcome* find(const std::string& id) const;
};

// Same seed and same graph give the same Outcome (and the same files) for any thread count:
// every node's random stream derives from (seed, run, node id), and per-run results are
// merged in run order (framework/src/run_dispatcher.hpp, shared with the MPI engine). An
// exception from a run stops the ensemble: no later run is handed out, and the lowest-numbered
// failing run's exception is rethrown with its run number, as DataError, whatever the timing.
Outcome run_graph(const Graph& g, const PluginRegistry& registry, const RunOptions& opt);

}  // namespace trackflow::host
