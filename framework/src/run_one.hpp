// Purpose: one Monte Carlo run on one graph instance — the engine's and the MPI engine's shared step: resets, start_run, the time-ordered merge of the sources, end_run — and the merge of one run into the ensemble's results.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/graph.hpp>
#include <trackflow/host/guard.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace trackflow::host {

// What one run leaves for the ordered reduction.
struct RunRecord {
  std::vector<std::unique_ptr<RunResult>> results;  // by node
  Diagnostics diagnostics;
  std::uint64_t source_items = 0;
  std::uint64_t measurements_processed = 0;
};

// The nodes of an instance as error messages and the crash handler name them.
NodeLabels labels_of(const Graph& g, const GraphInstance& inst);

// An Outcome before any run is merged: the nodes named, the filters counted.
Outcome empty_outcome(const Graph& g, std::uint64_t runs);

// The filters of an instance (the engine resets their adapted noise before every run).
std::vector<Filter*> filters_of(GraphInstance& inst);

// Runs `run` on `inst`: the adapters' tuning put back (so results never depend on which thread
// or process ran which run), start_run with the run's per-node seeds, the sources merged in time
// order (ties to the generator declared first), end_run. Marks the executing node for the crash
// handler; exceptions pass through (callers name the run and the plugin).
RunRecord run_one(const Graph& g, GraphInstance& inst, const std::vector<Filter*>& filters, std::uint64_t seed,
                  std::uint64_t run);

// The ordered reduction's bookkeeping for run `run` of `runs`: its item counts, and its diagnostics
// as the report shows them (a skip count per node with at most 5 examples, each prefixed with its
// run when there is more than one; at most 20 warnings in all). Call in run order.
void merge_run_diagnostics(const RunRecord& rec, std::uint64_t run, std::uint64_t runs, Outcome& out);

// Merges run `run` of `runs` into the ensemble: its per-run results into the aggregating
// instance's merge(), its counts and diagnostics into the Outcome. The dispatcher calls it in run
// order, so sums are identical for any thread or process count. A plugin that throws in merge()
// is reported with its node and that run (rethrow_from_plugin); the crash handler names them too.
void merge_run(GraphInstance& aggregate, const NodeLabels& labels, std::uint64_t run, std::uint64_t runs,
               RunRecord&& rec, Outcome& out);

// finish() of every node of the aggregating instance, on the calling thread, in graph order;
// a plugin that throws is reported with its node (rethrow_from_plugin).
void finish_all(const Graph& g, GraphInstance& aggregate, const NodeLabels& labels, const RunOptions& opt,
                std::uint64_t runs, Outcome& out);

}  // namespace trackflow::host
