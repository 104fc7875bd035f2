// Purpose: the one run dispatcher of both engines — the window of runs in flight, the run-order merge, the first failure (by run), progress — and the interfaces of the transports that carry its runs (local threads, MPI ranks).
#pragma once

#include "run_one.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace trackflow::host {

class RunDispatcher;

// What worker threads pull runs from and hand their results to: the dispatcher itself, or (on an
// MPI worker rank) the runs rank 0 assigned to this process.
class RunSource {
 public:
  virtual ~RunSource() = default;
  // The next run to execute; blocks while none can be handed out yet; none: stop.
  virtual std::optional<std::uint64_t> next_run() = 0;
  // Run `run` finished on instance `ran_on` (whose codecs can encode its per-run results).
  virtual void finished(std::uint64_t run, RunRecord&& rec, const GraphInstance& ran_on) = 0;
  // Run `run` failed, or (no run) a worker thread could not build its graph instance.
  virtual void failed(std::optional<std::uint64_t> run, std::exception_ptr error) = 0;
};

// Moves the dispatcher's runs to where they execute and their results back; everything else
// (order, window, failure, progress) is the dispatcher's.
class Transport {
 public:
  virtual ~Transport() = default;
  // How many runs may be handed out beyond the oldest one not yet merged (at least 1); a problem
  // with a setting becomes a warning.
  virtual std::uint64_t window(std::vector<std::string>& warnings) = 0;
  // The error as this transport reports a failure on this process: of run `run` (in the run or
  // in its merge), or of a worker's set-up (no run).
  virtual std::exception_ptr attribute(std::optional<std::uint64_t> run, std::exception_ptr error) const {
    (void)run;
    return error;
  }
  // Executes every run `d` hands out and returns each result or failure to it; returns once no
  // run is in flight and none will be handed out.
  virtual void carry(RunDispatcher& d) = 0;
};

// Hands out runs 0..runs-1 in order, at most `window` beyond the oldest run not merged, so a slow
// run cannot make finished ones pile up without bound; merges finished runs strictly in run order
// (sums identical for any number of threads or processes); keeps the failure of the lowest run
// (or a set-up failure before any), after which no run is handed out and later runs are dropped;
// shows progress. Thread-safe.
class RunDispatcher final : public RunSource {
 public:
  // Merges one run into the ensemble's results; called in run order, under the dispatcher's lock.
  using MergeRun = std::function<void(std::uint64_t run, RunRecord&& rec)>;
  using Progress = std::function<void(std::uint64_t done, std::uint64_t total)>;
  using Attribute = std::function<std::exception_ptr(std::optional<std::uint64_t>, std::exception_ptr)>;

  // `warnings` receives warn()'s lines (it is where MergeRun writes its own, under the same lock).
  RunDispatcher(std::uint64_t runs, std::uint64_t window, MergeRun merge, Progress progress, Attribute attribute,
                std::vector<std::string>& warnings);

  // Up to `n` runs to start now, in order; none when the window is full or nothing is left.
  std::vector<std::uint64_t> take(std::uint64_t n);
  // No run will be handed out any more: all were, or a run failed.
  bool exhausted() const;

  // RunSource, for threads of this process: waits for the window; failures are attributed.
  std::optional<std::uint64_t> next_run() override;
  void finished(std::uint64_t run, RunRecord&& rec, const GraphInstance& ran_on) override;
  void failed(std::optional<std::uint64_t> run, std::exception_ptr error) override;

  // A result or failure that another process attributed already.
  void complete(std::uint64_t run, RunRecord&& rec);
  void failed_elsewhere(std::optional<std::uint64_t> run, std::exception_ptr error);

  // A line for the summary's warnings (at most 20 in all).
  void warn(const std::string& line);
  bool has_failed() const;
  std::uint64_t merged() const;
  // Runs finished (merged or waiting for an earlier one).
  std::uint64_t completed() const;
  // Finished runs held until an earlier one is merged.
  std::size_t waiting();

  // For the coordinating thread: the progress display at most every 100 ms (it is cosmetic: a
  // display that throws is ignored), and a wait of at most `timeout` for a run to finish or fail.
  void show_progress();
  void wait_for_change(std::chrono::milliseconds timeout);

  // Once the transport has returned: rethrows the failure, or checks that every run was merged
  // and shows the final progress.
  void conclude();

 private:
  void record_failure(std::optional<std::uint64_t> run, std::exception_ptr error);

  const std::uint64_t runs_;
  const std::uint64_t window_;
  const MergeRun merge_;
  const Progress progress_;
  const Attribute attribute_;
  std::vector<std::string>& warnings_;

  // Merging (may be slow: a sink streams its file) has its own lock so that handing out runs
  // never waits for it. Lock order: merge_mutex_, then state_mutex_.
  std::mutex merge_mutex_;
  std::map<std::uint64_t, RunRecord> pending_;  // finished, waiting for an earlier run
  std::uint64_t next_merge_ = 0;

  mutable std::mutex state_mutex_;
  std::condition_variable changed_;  // a merge, a finished run or a failure
  std::uint64_t next_run_ = 0;
  std::uint64_t merged_ = 0;
  std::uint64_t completed_ = 0;
  std::uint64_t changes_ = 0;
  std::exception_ptr failure_;
  std::optional<std::uint64_t> failure_run_;  // none with a failure: a set-up failure
  std::chrono::steady_clock::time_point last_progress_{};
};

// The ensemble of `runs` runs over `transport`: merged into `aggregate` (an instance of `g`) in
// run order, finish() of every node, the Outcome with its wall time. On the calling thread:
// merges and finish() see opt.output_dir as output_directory().
Outcome dispatch_ensemble(const Graph& g, GraphInstance& aggregate, const RunOptions& opt, std::uint64_t runs,
                          Transport& transport);

}  // namespace trackflow::host
